#pragma once
/// @file
/// @brief The wire and in-pool layout of one depth frame: a fixed header followed by 64-byte
/// aligned structure-of-arrays fields. The same bytes live in a pool block (one process) or in an
/// iceoryx chunk (between processes), so a frame is written once, in place, and read where it lies.
///
/// Layout: FrameHeader (64 bytes), then x[n], y[n], z[n] (float), then rgb[n] and label[n] (uint32)
/// when the header's `fields` has the bit, each array starting on a 64-byte boundary; n = width *
/// height. Every reader validates type id, version and sizes before touching a point.
#include <array>
#include <cstddef>
#include <cstdint>
#include <span>
#include <string>

#include "core/result.hpp"
#include "kernels/point_cloud.hpp"

namespace orthoflow::engine {

inline constexpr std::uint32_t FRAME_TYPE_ID = 0x4652464FU;  ///< "OFRF" in little-endian bytes
inline constexpr std::uint16_t FRAME_VERSION = 1;
inline constexpr std::uint32_t FRAME_FIELD_RGB = 1U << 0;
inline constexpr std::uint32_t FRAME_FIELD_LABEL = 1U
                                                   << 1;  ///< ground-truth labels (synthetic, mOSD)

/// @brief First 64 bytes of every frame payload.
struct alignas(64) FrameHeader {
  std::uint32_t type_id = FRAME_TYPE_ID;
  std::uint16_t version = FRAME_VERSION;
  std::uint16_t reserved0 = 0;
  std::uint32_t width = 0;   ///< points per row
  std::uint32_t height = 0;  ///< rows (1 = unorganized)
  std::uint32_t fields = 0;  ///< FRAME_FIELD_* bits
  std::uint32_t reserved1 = 0;
  std::uint64_t frame_id = 0;
  std::int64_t sensor_stamp_ns = 0;
  std::int64_t host_stamp_ns = 0;
  std::uint64_t payload_bytes =
      0;  ///< header included; equals frame_payload_bytes(width, height, fields)
  /// "up" in the sensor frame (kernels::FrameInfo::up) as int16 / 32767 per axis; all zero (what
  /// writers before it left in these bytes) = unknown.
  std::array<std::int16_t, 3> up_q{};
  std::uint16_t up_age_ms = 0;  ///< age of the reading behind up_q, saturated at 65535
};
static_assert(sizeof(FrameHeader) == 64);

/// @brief The unit "up" vector a frame carries into @p up; false (up untouched) when it carries
/// none or the stored vector is not close to unit length.
[[nodiscard]] bool frame_up(const FrameHeader& header, std::array<float, 3>& up) noexcept;

/// @brief Bytes a frame of this shape occupies (header included), or 0 if the shape overflows
/// (more than 2^28 points). @note constexpr-friendly, no allocation.
[[nodiscard]] std::size_t frame_payload_bytes(std::uint32_t width, std::uint32_t height,
                                              std::uint32_t fields) noexcept;

/// @brief A validated read-only view of a frame payload.
struct FrameView {
  const FrameHeader* header = nullptr;
  kernels::CloudView cloud;
  std::span<const std::uint32_t> rgb;    ///< empty when absent
  std::span<const std::uint32_t> label;  ///< empty when absent
};

/// @brief Writable spans into a frame payload being filled in place.
struct FrameSpan {
  FrameHeader* header = nullptr;
  kernels::PointsSpan points;
  std::span<std::uint32_t> rgb;
  std::span<std::uint32_t> label;
};

/// @brief Why a payload is not a frame this build can read.
struct FrameError {
  enum class Code { TOO_SMALL, MISALIGNED, WRONG_TYPE, WRONG_VERSION, BAD_SHAPE, SIZE_MISMATCH };
  Code code = Code::TOO_SMALL;
  std::uint64_t expected = 0;
  std::uint64_t found = 0;
  /// @brief Full message, e.g. "frame payload: version 2, this build reads 1". Allocates.
  [[nodiscard]] std::string to_string() const;
};

/// @brief Writes a header for a width x height frame into @p bytes and returns spans to fill.
/// @pre bytes 64-byte aligned. @return TOO_SMALL / BAD_SHAPE / MISALIGNED when it cannot hold it.
/// @note Does not touch the point arrays (no value-initialisation): the caller fills them.
[[nodiscard]] Result<FrameSpan, FrameError> layout_frame(std::span<std::byte> bytes,
                                                         std::uint32_t width, std::uint32_t height,
                                                         std::uint32_t fields) noexcept;

/// @brief Validates @p bytes as a frame (type, version, shape, sizes) and views it. Never reads
/// past bytes.size(). Thread-safe; no allocation.
[[nodiscard]] Result<FrameView, FrameError> view_frame(std::span<const std::byte> bytes) noexcept;

/// @brief Copies a PointCloud (its rgb and label fields when present) into @p bytes as a frame,
/// with the cloud's stamps and frame id. @return the payload size written.
[[nodiscard]] Result<std::size_t, FrameError> write_frame(
    std::span<std::byte> bytes, const kernels::PointCloud& cloud) noexcept;

}  // namespace orthoflow::engine
