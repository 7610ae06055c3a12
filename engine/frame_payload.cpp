#include "engine/frame_payload.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>

namespace orthoflow::engine {

namespace {

constexpr std::size_t ALIGN = 64;
constexpr std::uint64_t MAX_POINTS = std::uint64_t{1} << 28;

constexpr std::size_t align_up(std::size_t n) noexcept { return (n + ALIGN - 1) / ALIGN * ALIGN; }

// Offsets of the arrays after the header, in the order of the layout comment in the header file.
struct Offsets {
  std::size_t x = 0, y = 0, z = 0, rgb = 0, label = 0, end = 0;
};

Offsets offsets(std::size_t n, std::uint32_t fields) noexcept {
  Offsets o;
  const std::size_t floats = align_up(n * sizeof(float));
  const std::size_t words = align_up(n * sizeof(std::uint32_t));
  o.x = sizeof(FrameHeader);
  o.y = o.x + floats;
  o.z = o.y + floats;
  std::size_t next = o.z + floats;
  if ((fields & FRAME_FIELD_RGB) != 0U) {
    o.rgb = next;
    next += words;
  }
  if ((fields & FRAME_FIELD_LABEL) != 0U) {
    o.label = next;
    next += words;
  }
  o.end = next;
  return o;
}

template <class T, class Byte>
std::span<T> array_at(Byte* base, std::size_t offset, std::size_t n) noexcept {
  if (offset == 0) { return {}; }
  return {reinterpret_cast<T*>(base + offset),
          n};  // NOLINT: the layout is 64-byte aligned by construction
}

}  // namespace

std::size_t frame_payload_bytes(std::uint32_t width, std::uint32_t height,
                                std::uint32_t fields) noexcept {
  const std::uint64_t n = std::uint64_t{width} * height;
  if (n > MAX_POINTS) { return 0; }
  return offsets(static_cast<std::size_t>(n), fields).end;
}

std::string FrameError::to_string() const {
  const std::string e = std::to_string(expected);
  const std::string f = std::to_string(found);
  switch (code) {
    case Code::TOO_SMALL:
      return "frame payload: " + f + " bytes, the frame needs " + e;
    case Code::MISALIGNED:
      return "frame payload: not 64-byte aligned";
    case Code::WRONG_TYPE:
      return "frame payload: type id " + f + " is not a frame (" + e + ")";
    case Code::WRONG_VERSION:
      return "frame payload: version " + f + ", this build reads " + e;
    case Code::BAD_SHAPE:
      return "frame payload: " + f + " points is not a valid shape (at most " + e + ")";
    case Code::SIZE_MISMATCH:
      return "frame payload: header says " + f + " bytes, the shape needs " + e;
  }
  return "frame payload: unknown error";
}

Result<FrameSpan, FrameError> layout_frame(std::span<std::byte> bytes, std::uint32_t width,
                                           std::uint32_t height, std::uint32_t fields) noexcept {
  using Code = FrameError::Code;
  if (reinterpret_cast<std::uintptr_t>(bytes.data()) % ALIGN != 0) {
    return err(FrameError{Code::MISALIGNED, 0, 0});
  }
  const std::size_t need = frame_payload_bytes(width, height, fields);
  if (need == 0 || height == 0) {
    return err(FrameError{Code::BAD_SHAPE, MAX_POINTS, std::uint64_t{width} * height});
  }
  if (bytes.size() < need) { return err(FrameError{Code::TOO_SMALL, need, bytes.size()}); }
  auto* header = new (bytes.data()) FrameHeader{};
  header->width = width;
  header->height = height;
  header->fields = fields;
  header->payload_bytes = need;
  const std::size_t n = std::size_t{width} * height;
  const Offsets o = offsets(n, fields);
  std::byte* base = bytes.data();
  return FrameSpan{
      header,
      {array_at<float>(base, o.x, n), array_at<float>(base, o.y, n), array_at<float>(base, o.z, n)},
      array_at<std::uint32_t>(base, o.rgb, n),
      array_at<std::uint32_t>(base, o.label, n)};
}

Result<FrameView, FrameError> view_frame(std::span<const std::byte> bytes) noexcept {
  using Code = FrameError::Code;
  if (bytes.size() < sizeof(FrameHeader)) {
    return err(FrameError{Code::TOO_SMALL, sizeof(FrameHeader), bytes.size()});
  }
  if (reinterpret_cast<std::uintptr_t>(bytes.data()) % ALIGN != 0) {
    return err(FrameError{Code::MISALIGNED, 0, 0});
  }
  const auto* header =
      reinterpret_cast<const FrameHeader*>(bytes.data());  // NOLINT: checked size and alignment
  if (header->type_id != FRAME_TYPE_ID) {
    return err(FrameError{Code::WRONG_TYPE, FRAME_TYPE_ID, header->type_id});
  }
  if (header->version != FRAME_VERSION) {
    return err(FrameError{Code::WRONG_VERSION, FRAME_VERSION, header->version});
  }
  const std::size_t need = frame_payload_bytes(header->width, header->height, header->fields);
  if (need == 0 || header->height == 0) {
    return err(
        FrameError{Code::BAD_SHAPE, MAX_POINTS, std::uint64_t{header->width} * header->height});
  }
  if (header->payload_bytes != need) {
    return err(FrameError{Code::SIZE_MISMATCH, need, header->payload_bytes});
  }
  if (bytes.size() < need) { return err(FrameError{Code::TOO_SMALL, need, bytes.size()}); }
  const std::size_t n = std::size_t{header->width} * header->height;
  const Offsets o = offsets(n, header->fields);
  const std::byte* base = bytes.data();
  const kernels::PointsView points{array_at<const float>(base, o.x, n),
                                   array_at<const float>(base, o.y, n),
                                   array_at<const float>(base, o.z, n)};
  return FrameView{header,
                   {points, header->width, header->height},
                   array_at<const std::uint32_t>(base, o.rgb, n),
                   array_at<const std::uint32_t>(base, o.label, n)};
}

Result<std::size_t, FrameError> write_frame(std::span<std::byte> bytes,
                                            const kernels::PointCloud& cloud) noexcept {
  const std::uint32_t fields = (cloud.has(kernels::Field::RGB) ? FRAME_FIELD_RGB : 0U) |
                               (cloud.has(kernels::Field::LABEL) ? FRAME_FIELD_LABEL : 0U);
  const std::uint32_t height = std::max<std::uint32_t>(cloud.height(), 1);
  auto laid = layout_frame(bytes, cloud.width(), height, fields);
  if (!laid) { return err(laid.error()); }
  FrameSpan& f = *laid;
  f.header->frame_id = cloud.info.frame_id;
  f.header->sensor_stamp_ns = cloud.info.sensor_stamp_ns;
  f.header->host_stamp_ns = cloud.info.host_stamp_ns;
  const auto& up = cloud.info.up;
  const float norm = std::sqrt(up[0] * up[0] + up[1] * up[1] + up[2] * up[2]);
  if (std::isfinite(norm) && norm > 0.5F && norm < 1.5F) {
    for (int k = 0; k < 3; ++k)
      f.header->up_q[k] = static_cast<std::int16_t>(std::lround(32767.0F * up[k] / norm));
    f.header->up_age_ms =
        static_cast<std::uint16_t>(std::min<std::uint32_t>(cloud.info.up_age_ms, 65535));
  }
  std::ranges::copy(cloud.x(), f.points.x.begin());
  std::ranges::copy(cloud.y(), f.points.y.begin());
  std::ranges::copy(cloud.z(), f.points.z.begin());
  if (!f.rgb.empty()) { std::ranges::copy(cloud.rgb(), f.rgb.begin()); }
  if (!f.label.empty()) { std::ranges::copy(cloud.label(), f.label.begin()); }
  return static_cast<std::size_t>(f.header->payload_bytes);
}

bool frame_up(const FrameHeader& header, std::array<float, 3>& up) noexcept {
  std::array<float, 3> v{};
  float sq = 0.0F;
  for (int k = 0; k < 3; ++k) {
    v[k] = static_cast<float>(header.up_q[k]) / 32767.0F;
    sq += v[k] * v[k];
  }
  if (!(sq > 0.81F && sq < 1.21F)) return false;  // none (all zero), or not a unit vector
  const float norm = std::sqrt(sq);
  for (int k = 0; k < 3; ++k) up[k] = v[k] / norm;
  return true;
}

}  // namespace orthoflow::engine
