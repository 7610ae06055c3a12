#pragma once
/// @file
/// @brief ObjectListPayload: the recognised objects of one frame as one fixed-size POD: what the
/// tabletop graph's objects_output node hands to in-process consumers
/// (graphs/nodes/objects_output.hpp) and, through ipc_publish, to the iceoryx topic
/// `orthoflow/<graph>/objects`. With frame_payload.hpp this is the one place orthoflow's message
/// schemas live; the transport and every consumer include it. Same header rules as every payload:
/// type id, version, payload_bytes at offset 48. Version 2: decided_ns and age_ns (reserved in 1),
/// per-object sensor-frame box and flags.
#include <cstddef>
#include <cstdint>
#include <type_traits>

#include "core/fixed_text.hpp"

namespace orthoflow::engine {

inline constexpr std::uint32_t OBJECT_LIST_TYPE_ID =
    0x4C4F464FU;  ///< "OFOL" in little-endian bytes
inline constexpr std::uint16_t OBJECT_LIST_VERSION = 2;
inline constexpr std::uint32_t OBJECT_LIST_CAPACITY = 64;

/// @brief One object: track, label, pose frame and size.
struct ObjectEntry {
  std::uint64_t track_id;  ///< 0: not tracked
  core::Text label;        ///< the category, or empty when Unknown
  float score;             ///< recognition score (learner's decision value; NaN before any lesson)
  std::uint32_t unknown;   ///< 1 if no known category matched (or the object was not recognised)
  float centroid[3];       ///< metres, sensor frame
  float frame[16];         ///< sensor-to-object transform, row-major 4x4 (GOOD's object frame)
  float bbox[3];           ///< bounding-box extents along the object frame's axes, metres
  std::uint32_t point_count;
  float bbox_min[3];  ///< axis-aligned box in the sensor frame, metres
  float bbox_max[3];
  std::uint32_t flags;  ///< OBJECT_* bits below
};

inline constexpr std::uint32_t OBJECT_DESCRIBED = 1U << 0;  ///< it has a descriptor (and a frame)
inline constexpr std::uint32_t OBJECT_MOVING = 1U << 1;     ///< the tracker sees it move
inline constexpr std::uint32_t OBJECT_KEY_VIEW =
    1U << 2;  ///< this view is one of its track's key views
inline constexpr std::uint32_t OBJECT_FRAGMENT =
    1U << 3;  ///< a piece of an object with the same track id
inline constexpr std::uint32_t OBJECT_TAUGHT = 1U << 4;  ///< this view was taught in this frame
/// The answer is its track's from an earlier frame: the recognise node's period had not run out.
inline constexpr std::uint32_t OBJECT_CARRIED = 1U << 5;

/// @brief Header (64 bytes) + count + up to 64 objects. The user-written empty constructors leave
/// the members uninitialised on purpose: iceoryx's typed loan() value-initialises its payload, and
/// zeroing this struct on every frame is wasted work; call reset_header() and fill what you use.
struct alignas(64) ObjectListPayload {
  std::uint32_t type_id;
  std::uint16_t version;
  std::uint16_t reserved0;
  std::uint32_t count;  ///< objects[0, count) are valid; <= OBJECT_LIST_CAPACITY
  /// The frame's table verdict: kernels::TableReason + 1 (1 accepted, 2 held, 3 no_plane,
  /// 4 not_level, 5 out_of_range, 6 too_small); 0: not reported (reserved before issue 50).
  std::uint8_t table_reason;
  std::uint8_t gravity;  ///< graphs::Gravity + 1 (1 none, 2 sensor, 3 configured); 0: not reported
  std::uint16_t reserved1;
  std::uint64_t frame_id;
  std::int64_t sensor_stamp_ns;
  std::int64_t host_stamp_ns;
  std::int64_t decided_ns;      ///< steady-clock time the objects were decided (recognised), ns
  std::uint64_t payload_bytes;  ///< offset 48: sizeof(ObjectListPayload)
  std::int64_t age_ns;  ///< decided_ns minus the frame's host stamp: the frame's age at decision
  ObjectEntry objects[OBJECT_LIST_CAPACITY];

  ObjectListPayload() noexcept {
  }  // NOLINT: deliberately leaves the fields uninitialised (see above)

  /// @brief Writes type id, version, payload_bytes and zero count/stamps/reserved. No allocation.
  void reset_header() noexcept {
    type_id = OBJECT_LIST_TYPE_ID;
    version = OBJECT_LIST_VERSION;
    reserved0 = 0;
    count = 0;
    table_reason = 0;
    gravity = 0;
    reserved1 = 0;
    frame_id = 0;
    sensor_stamp_ns = 0;
    host_stamp_ns = 0;
    decided_ns = 0;
    payload_bytes = sizeof(ObjectListPayload);
    age_ns = 0;
  }
};
static_assert(offsetof(ObjectListPayload, payload_bytes) == 48);
static_assert(offsetof(ObjectListPayload, objects) == 64);
static_assert(std::is_trivially_copyable_v<ObjectListPayload>);

}  // namespace orthoflow::engine
