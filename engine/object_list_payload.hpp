#pragma once
/// @file
/// @brief ObjectListPayload: the recognised objects of one frame as one fixed-size POD, published
/// over IPC (`orthoflow/<graph>/objects`) or held in a pool block. Same header rules as every
/// payload: type id, version, payload_bytes at offset 48.
#include <cstddef>
#include <cstdint>
#include <type_traits>

#include "core/fixed_text.hpp"

namespace orthoflow::engine {

inline constexpr std::uint32_t OBJECT_LIST_TYPE_ID = 0x4C4F464FU;  ///< "OFOL" in little-endian bytes
inline constexpr std::uint16_t OBJECT_LIST_VERSION = 1;
inline constexpr std::uint32_t OBJECT_LIST_CAPACITY = 64;

/// @brief One object: track, label, pose frame and size.
struct ObjectEntry {
  std::uint64_t track_id;
  core::Text label;                ///< the category, or empty when unknown
  float score;                     ///< recognition score (lower distance = better, see learning/)
  std::uint32_t unknown;           ///< 1 if no known category matched
  float centroid[3];               ///< metres, sensor frame
  float frame[16];                 ///< object-to-sensor transform, row-major 4x4
  float bbox[3];                   ///< bounding-box extents along the object frame's axes, metres
  std::uint32_t point_count;
};

/// @brief Header (64 bytes) + count + up to 64 objects. The user-written empty constructors leave
/// the members uninitialised on purpose: iceoryx's typed loan() value-initialises its payload, and
/// zeroing this struct on every frame is wasted work; call reset_header() and fill what you use.
struct alignas(64) ObjectListPayload {
  std::uint32_t type_id;
  std::uint16_t version;
  std::uint16_t reserved0;
  std::uint32_t count;  ///< objects[0, count) are valid; <= OBJECT_LIST_CAPACITY
  std::uint32_t reserved1;
  std::uint64_t frame_id;
  std::int64_t sensor_stamp_ns;
  std::int64_t host_stamp_ns;
  std::uint64_t reserved2;
  std::uint64_t payload_bytes;  ///< offset 48: sizeof(ObjectListPayload)
  std::uint64_t reserved3;
  ObjectEntry objects[OBJECT_LIST_CAPACITY];

  ObjectListPayload() noexcept {}  // NOLINT: deliberately leaves the fields uninitialised (see above)

  /// @brief Writes type id, version, payload_bytes and zero count/stamps/reserved. No allocation.
  void reset_header() noexcept {
    type_id = OBJECT_LIST_TYPE_ID;
    version = OBJECT_LIST_VERSION;
    reserved0 = 0;
    count = 0;
    reserved1 = 0;
    frame_id = 0;
    sensor_stamp_ns = 0;
    host_stamp_ns = 0;
    reserved2 = 0;
    payload_bytes = sizeof(ObjectListPayload);
    reserved3 = 0;
  }
};
static_assert(offsetof(ObjectListPayload, payload_bytes) == 48);
static_assert(offsetof(ObjectListPayload, objects) == 64);
static_assert(std::is_trivially_copyable_v<ObjectListPayload>);

}  // namespace orthoflow::engine
