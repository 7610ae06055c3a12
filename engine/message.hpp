#pragma once
/// @file
/// @brief Message: the one small fixed type every port carries. Payload data lives in a pool block
/// shared by handle, so copying a message never allocates (zero-copy hand-over, like nodelets).
#include <cstdint>

#include "memory_pool/block_pool.hpp"

namespace orthoflow::engine {

/// @brief A frame (or one object of a frame) travelling along an edge.
/// @note Copying is cheap and allocation-free (one atomic increment if a payload is attached).
struct Message {
  std::uint64_t frame_id = 0;      ///< assigned by the source: 0, 1, 2, ... without gaps
  std::int64_t stamp_ns = 0;       ///< steady-clock time the source produced the frame
  std::uint32_t object_index = 0;  ///< per-object multiplexing: which object of the frame
  std::uint32_t object_count = 1;  ///< objects the frame was split into (0 = frame had none)
  std::uint32_t port = 0;          ///< input port index at the receiving node (set by the engine)
  std::uint32_t slot = 0;          ///< set by the engine: in [0, max_in_flight), unique among the
                                   ///< frames in flight; key per-frame state (joins) by it
  bool skipped = false;            ///< tombstone: frame dropped or produced no data upstream
  std::int64_t value = 0;          ///< small scalar result (generic nodes use it; domain nodes may)
  memory_pool::BlockHandle payload;  ///< optional data block (empty handle = none)
};

}  // namespace orthoflow::engine
