#pragma once
/// @file
/// @brief Adapters between orthoflow's structure-of-arrays PointCloud and array-of-structs layouts
/// described by field descriptors (ROS sensor_msgs/PointCloud2 style, PCD binary records) or by a
/// point struct (PCL's PointXYZRGBA and friends). Kernels never see these layouts (STYLE rule 11).
#include <bit>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <span>
#include <string>
#include <vector>

#include "kernels/point_cloud.hpp"

namespace orthoflow::formats {

static_assert(std::endian::native == std::endian::little,
              "PCD/PointCloud2 records are little-endian");

/// @brief Scalar types with the ROS PointField datatype codes.
enum class ScalarType : std::uint8_t {
  INT8 = 1,
  UINT8,
  INT16,
  UINT16,
  INT32,
  UINT32,
  FLOAT32,
  FLOAT64
};

/// @brief Size in bytes of one scalar of @p type.
[[nodiscard]] std::uint32_t scalar_size(ScalarType type) noexcept;

/// @brief One field of a record: name, byte offset in the record, scalar type, element count.
struct PointField {
  std::string name;
  std::uint32_t offset = 0;
  ScalarType type = ScalarType::FLOAT32;
  std::uint32_t count = 1;
  [[nodiscard]] std::uint32_t bytes() const noexcept { return scalar_size(type) * count; }
  bool operator==(const PointField&) const = default;
};

/// @brief Which PointCloud buffer a field name fills: x, y, z, rgb/rgba, label, normal_x/y/z.
enum class FieldTarget : std::uint8_t { NONE, X, Y, Z, RGB, LABEL, NORMAL_X, NORMAL_Y, NORMAL_Z };

/// @brief The target of a field name (NONE for fields orthoflow does not keep, which are skipped).
[[nodiscard]] FieldTarget field_target(const std::string& name) noexcept;

/// @brief The cloud's float buffer for a coordinate or normal target; empty for others.
[[nodiscard]] std::span<const float> float_buffer(const kernels::PointCloud& cloud,
                                                  FieldTarget target) noexcept;

/// @brief The records orthoflow writes for @p cloud: x y z, then rgba, label, normal_x/y/z if
/// present, all 4-byte scalars at consecutive offsets.
[[nodiscard]] std::vector<PointField> fields_for(const kernels::PointCloud& cloud);

/// @brief Sum of the fields' sizes (the record size when fields are packed).
[[nodiscard]] std::uint32_t packed_size(std::span<const PointField> fields) noexcept;

/// @brief Adds to @p cloud (already sized) the optional fields that @p fields carry.
void add_fields_for(std::span<const PointField> fields, kernels::PointCloud& cloud);

/// @brief Copies element 0 of @p field for points [0, cloud.size()) into the cloud's matching
/// buffer. Point i's value starts at base + i * stride. Float fields keep their bits; integers
/// convert.
/// @pre the memory range is valid for cloud.size() records; field targets something.
void decode_field(const char* base, std::size_t stride, const PointField& field,
                  kernels::PointCloud& cloud) noexcept;

/// @brief Writes the cloud's buffer that @p field names into base + i * stride (4-byte fields
/// only).
void encode_field(const kernels::PointCloud& cloud, const PointField& field, char* base,
                  std::size_t stride) noexcept;

/// @brief Decodes @p n = cloud.size() records of @p point_step bytes (PointCloud2 / PCD binary).
/// @pre data.size() >= cloud.size() * point_step
void decode_records(std::span<const char> data, std::span<const PointField> fields,
                    std::size_t point_step, kernels::PointCloud& cloud) noexcept;

/// @brief Encodes the cloud into packed records laid out by @p fields (from fields_for()).
/// @pre out.size() >= cloud.size() * packed_size(fields)
void encode_records(const kernels::PointCloud& cloud, std::span<const PointField> fields,
                    std::span<char> out) noexcept;

/// @brief Copies an array of point structs with members x, y, z (and, if present, rgba) into @p
/// cloud, unorganized. Works with PCL's PointXYZ / PointXYZRGBA without depending on PCL.
template <class PointT>
void from_aos(std::span<const PointT> points, kernels::PointCloud& cloud) {
  cloud.resize_unorganized(points.size());
  constexpr bool HAS_RGBA = requires(const PointT& p) { p.rgba; };
  if constexpr (HAS_RGBA) { cloud.add_field(kernels::Field::RGB); }
  for (std::size_t i = 0; i < points.size(); ++i) {
    cloud.x()[i] = points[i].x;
    cloud.y()[i] = points[i].y;
    cloud.z()[i] = points[i].z;
    if constexpr (HAS_RGBA) {
      std::memcpy(&cloud.rgb()[i], &points[i].rgba, sizeof(std::uint32_t));
    }
  }
}

/// @brief Copies @p cloud into point structs (x, y, z and, if the struct has it, rgba; 0 when
/// absent).
/// @pre out.size() >= cloud.size()
template <class PointT>
void to_aos(const kernels::PointCloud& cloud, std::span<PointT> out) {
  constexpr bool HAS_RGBA = requires(PointT & p) { p.rgba; };
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    out[i].x = cloud.x()[i];
    out[i].y = cloud.y()[i];
    out[i].z = cloud.z()[i];
    if constexpr (HAS_RGBA) {
      const std::uint32_t rgba = cloud.has(kernels::Field::RGB) ? cloud.rgb()[i] : 0U;
      std::memcpy(&out[i].rgba, &rgba, sizeof(std::uint32_t));
    }
  }
}

}  // namespace orthoflow::formats
