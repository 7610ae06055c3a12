#pragma once
/// @file
/// @brief FrameRef: a 64-byte record that a pool block holds instead of a frame when the frame's
/// bytes stay where they arrived (an iceoryx chunk held by `ipc_subscribe`). Nodes that read frames
/// call resolve_frame_bytes() on their block and get the frame bytes wherever they live.
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <span>

#include "engine/frame_payload.hpp"

namespace orthoflow::engine {

/// @brief Type id of a FrameRef: the frame id with its high half inverted, so that no frame reader
/// mistakes a reference for a frame ("OFRF" ^ 0xFFFF0000).
inline constexpr std::uint32_t FRAME_REF_TYPE_ID = FRAME_TYPE_ID ^ 0xFFFF0000U;
inline constexpr std::uint16_t FRAME_REF_VERSION = 1;

/// @brief Points at frame bytes owned by someone else (the subscribing node keeps the chunk alive
/// as long as the block holding this record is alive). Same header rules as every payload: type id,
/// version, payload_bytes (= 64) at offset 48.
struct alignas(64) FrameRef {
  std::uint32_t type_id = FRAME_REF_TYPE_ID;
  std::uint16_t version = FRAME_REF_VERSION;
  std::uint16_t reserved0 = 0;
  std::uint32_t reserved1 = 0;
  std::uint32_t reserved2 = 0;
  const std::byte* data = nullptr;  ///< first byte of the referenced frame (its FrameHeader)
  std::uint64_t size = 0;           ///< bytes referenced (the frame's payload_bytes)
  std::uint64_t sequence = 0;       ///< IPC sequence number of the chunk (diagnostics)
  std::uint64_t reserved3 = 0;
  std::uint64_t payload_bytes = 64;  ///< offset 48, like FrameHeader::payload_bytes
  std::uint64_t reserved4 = 0;
};
static_assert(sizeof(FrameRef) == 64);
static_assert(offsetof(FrameRef, payload_bytes) == 48);

/// @brief The frame bytes a block stands for: the referenced bytes if @p block starts with a
/// FrameRef, else @p block itself. Thread-safe, no allocation.
/// @pre If the block holds a FrameRef, its target is alive (guaranteed while the block is held).
[[nodiscard]] inline std::span<const std::byte> resolve_frame_bytes(
    std::span<const std::byte> block) noexcept {
  if (block.size() < sizeof(FrameRef)) return block;
  std::uint32_t type_id = 0;
  std::uint16_t version = 0;
  std::memcpy(&type_id, block.data(), sizeof(type_id));
  std::memcpy(&version, block.data() + 4, sizeof(version));
  if (type_id != FRAME_REF_TYPE_ID || version != FRAME_REF_VERSION) return block;
  FrameRef ref;
  std::memcpy(&ref, block.data(), sizeof(ref));
  return {ref.data, static_cast<std::size_t>(ref.size)};
}

}  // namespace orthoflow::engine
