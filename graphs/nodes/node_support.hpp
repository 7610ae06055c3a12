#pragma once
/// @file
/// @brief What every tabletop node kind shares: its ports, the frame block of a message, and the
/// frame capacity derived from the graph's pool.
#include <memory>
#include <span>
#include <string>

#include "core/result.hpp"
#include "engine/node.hpp"
#include "engine/params.hpp"
#include "graphs/frame/frame_block.hpp"

namespace orthoflow::graphs {

/// @brief Factory result of every node kind.
using NodeResult = Result<std::unique_ptr<engine::Node>, std::string>;

/// @brief Port lists used by the tabletop kinds ("frame": a FrameBlock; "object": one object of
/// it).
inline const engine::PortSpec FRAME_IN{"in", "frame", true};
inline const engine::PortSpec FRAME_OUT{"out", "frame", false};
inline const engine::PortSpec OBJECT_IN{"in", "object", true};
inline const engine::PortSpec OBJECT_OUT{"out", "object", false};

/// @brief Frame capacity of the graph's pool blocks, or an error naming the node if a block is too
/// small for even a tiny frame (start-up only).
[[nodiscard]] Result<std::size_t, std::string> frame_capacity(const engine::NodeContext& context);

/// @brief A source's error when the pool's blocks hold @p capacity points, fewer than a 640x480
/// frame: the block_bytes the graph needs, with its descriptor room (start-up only).
[[nodiscard]] std::string full_frame_too_large(std::string_view kind, std::size_t capacity,
                                               const engine::NodeContext& context);

/// @brief The frame block a message carries. @pre message.payload holds a block of the graph's
/// pool.
[[nodiscard]] inline FrameBlock block_of(const engine::Message& message,
                                         std::size_t capacity) noexcept {
  return FrameBlock(message.payload.bytes(), capacity);
}

/// @brief Unwraps a parameter result into @p out, or returns false and keeps the first error.
template <class T, class U>
bool take(Result<T, std::string> result, U& out, std::string& error) {
  if (!result) {
    if (error.empty()) error = result.error();
    return false;
  }
  out = static_cast<U>(*result);
  return true;
}

}  // namespace orthoflow::graphs
