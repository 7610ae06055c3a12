#include "formats/point_fields.hpp"

#include <cstring>

namespace orthoflow::formats {
namespace {

template <class T>
T load(const char* p) noexcept {
  T v;
  std::memcpy(&v, p, sizeof(T));
  return v;
}

/// Reads one scalar of any type as double (exact for every integer type up to 32 bits).
double load_as_double(const char* p, ScalarType type) noexcept {
  switch (type) {
    case ScalarType::INT8:
      return load<std::int8_t>(p);
    case ScalarType::UINT8:
      return load<std::uint8_t>(p);
    case ScalarType::INT16:
      return load<std::int16_t>(p);
    case ScalarType::UINT16:
      return load<std::uint16_t>(p);
    case ScalarType::INT32:
      return load<std::int32_t>(p);
    case ScalarType::UINT32:
      return load<std::uint32_t>(p);
    case ScalarType::FLOAT32:
      return static_cast<double>(load<float>(p));
    case ScalarType::FLOAT64:
      return load<double>(p);
  }
  return 0.0;
}

void decode_float(const char* base, std::size_t stride, ScalarType type,
                  std::span<float> out) noexcept {
  if (type == ScalarType::FLOAT32) {  // bit copy: keeps NaN payloads and signed zeros
    for (std::size_t i = 0; i < out.size(); ++i) {
      std::memcpy(&out[i], base + i * stride, sizeof(float));
    }
    return;
  }
  for (std::size_t i = 0; i < out.size(); ++i) {
    out[i] = static_cast<float>(load_as_double(base + i * stride, type));
  }
}

void decode_u32(const char* base, std::size_t stride, ScalarType type,
                std::span<std::uint32_t> out) noexcept {
  if (scalar_size(type) == 4) {  // rgb is declared F 4 by PCL: keep the bits whatever the type
    for (std::size_t i = 0; i < out.size(); ++i) { std::memcpy(&out[i], base + i * stride, 4); }
    return;
  }
  for (std::size_t i = 0; i < out.size(); ++i) {
    const double v = load_as_double(base + i * stride, type);
    out[i] = (v >= 0.0 && v <= 4294967295.0) ? static_cast<std::uint32_t>(v) : 0U;
  }
}

}  // namespace

std::span<const float> float_buffer(const kernels::PointCloud& cloud, FieldTarget t) noexcept {
  switch (t) {
    case FieldTarget::X:
      return cloud.x();
    case FieldTarget::Y:
      return cloud.y();
    case FieldTarget::Z:
      return cloud.z();
    case FieldTarget::NORMAL_X:
      return cloud.normal_x();
    case FieldTarget::NORMAL_Y:
      return cloud.normal_y();
    case FieldTarget::NORMAL_Z:
      return cloud.normal_z();
    default:
      return {};
  }
}

namespace {

/// The writable buffer behind float_buffer(): the same selection, on a cloud the caller may change.
std::span<float> float_target(kernels::PointCloud& cloud, FieldTarget t) noexcept {
  const std::span<const float> view = float_buffer(cloud, t);
  return {const_cast<float*>(view.data()), view.size()};  // NOLINT: the cloud itself is not const
}

}  // namespace

std::uint32_t scalar_size(ScalarType type) noexcept {
  switch (type) {
    case ScalarType::INT8:
    case ScalarType::UINT8:
      return 1;
    case ScalarType::INT16:
    case ScalarType::UINT16:
      return 2;
    case ScalarType::INT32:
    case ScalarType::UINT32:
    case ScalarType::FLOAT32:
      return 4;
    case ScalarType::FLOAT64:
      return 8;
  }
  return 0;
}

FieldTarget field_target(const std::string& name) noexcept {
  if (name == "x") { return FieldTarget::X; }
  if (name == "y") { return FieldTarget::Y; }
  if (name == "z") { return FieldTarget::Z; }
  if (name == "rgb" || name == "rgba") { return FieldTarget::RGB; }
  if (name == "label") { return FieldTarget::LABEL; }
  if (name == "normal_x") { return FieldTarget::NORMAL_X; }
  if (name == "normal_y") { return FieldTarget::NORMAL_Y; }
  if (name == "normal_z") { return FieldTarget::NORMAL_Z; }
  return FieldTarget::NONE;
}

std::vector<PointField> fields_for(const kernels::PointCloud& cloud) {
  std::vector<PointField> fields;
  auto add = [&fields](const char* name, ScalarType type) {
    const std::uint32_t offset = fields.empty() ? 0U : fields.back().offset + fields.back().bytes();
    fields.push_back(PointField{name, offset, type, 1});
  };
  add("x", ScalarType::FLOAT32);
  add("y", ScalarType::FLOAT32);
  add("z", ScalarType::FLOAT32);
  if (cloud.has(kernels::Field::RGB)) { add("rgba", ScalarType::UINT32); }
  if (cloud.has(kernels::Field::LABEL)) { add("label", ScalarType::UINT32); }
  if (cloud.has(kernels::Field::NORMALS)) {
    add("normal_x", ScalarType::FLOAT32);
    add("normal_y", ScalarType::FLOAT32);
    add("normal_z", ScalarType::FLOAT32);
  }
  return fields;
}

std::uint32_t packed_size(std::span<const PointField> fields) noexcept {
  std::uint32_t total = 0;
  for (const PointField& f : fields) { total += f.bytes(); }
  return total;
}

void add_fields_for(std::span<const PointField> fields, kernels::PointCloud& cloud) {
  for (const PointField& f : fields) {
    switch (field_target(f.name)) {
      case FieldTarget::RGB:
        cloud.add_field(kernels::Field::RGB);
        break;
      case FieldTarget::LABEL:
        cloud.add_field(kernels::Field::LABEL);
        break;
      case FieldTarget::NORMAL_X:
      case FieldTarget::NORMAL_Y:
      case FieldTarget::NORMAL_Z:
        cloud.add_field(kernels::Field::NORMALS);
        break;
      default:
        break;
    }
  }
}

void decode_field(const char* base, std::size_t stride, const PointField& field,
                  kernels::PointCloud& cloud) noexcept {
  const FieldTarget t = field_target(field.name);
  if (t == FieldTarget::RGB) {
    decode_u32(base, stride, field.type, cloud.rgb());
  } else if (t == FieldTarget::LABEL) {
    decode_u32(base, stride, field.type, cloud.label());
  } else if (t != FieldTarget::NONE) {
    decode_float(base, stride, field.type, float_target(cloud, t));
  }
}

void encode_field(const kernels::PointCloud& cloud, const PointField& field, char* base,
                  std::size_t stride) noexcept {
  const FieldTarget t = field_target(field.name);
  const std::size_t n = cloud.size();
  if (t == FieldTarget::RGB || t == FieldTarget::LABEL) {
    const std::span<const std::uint32_t> src =
        (t == FieldTarget::RGB) ? cloud.rgb() : cloud.label();
    for (std::size_t i = 0; i < n; ++i) { std::memcpy(base + i * stride, &src[i], 4); }
    return;
  }
  const std::span<const float> src = float_buffer(cloud, t);
  for (std::size_t i = 0; i < src.size(); ++i) { std::memcpy(base + i * stride, &src[i], 4); }
}

void decode_records(std::span<const char> data, std::span<const PointField> fields,
                    std::size_t point_step, kernels::PointCloud& cloud) noexcept {
  if (cloud.empty()) { return; }  // an empty buffer may have no address to offset from
  for (const PointField& f : fields) { decode_field(data.data() + f.offset, point_step, f, cloud); }
}

void encode_records(const kernels::PointCloud& cloud, std::span<const PointField> fields,
                    std::span<char> out) noexcept {
  if (cloud.empty()) { return; }
  const std::size_t step = packed_size(fields);
  for (const PointField& f : fields) { encode_field(cloud, f, out.data() + f.offset, step); }
}

}  // namespace orthoflow::formats
