#pragma once
// Shared by the reader fuzzers: whatever a reader accepts must survive a PCD write/read round trip
// in every encoding with every field bit for bit (NaN payloads included), else the fuzzer traps.
#include <cmath>
#include <cstring>
#include <span>
#include <string>

#include "formats/pcd_io.hpp"

namespace orthoflow_fuzz {

template <class T>
bool same_bits(std::span<const T> a, std::span<const T> b) {
  return a.size() == b.size() &&
         (a.empty() || std::memcmp(a.data(), b.data(), a.size_bytes()) == 0);
}

/// Equal bits, or both NaN: text ("nan") does not carry a NaN's sign and payload.
inline bool same_value(std::span<const float> a, std::span<const float> b) {
  if (a.size() != b.size()) { return false; }
  for (std::size_t i = 0; i < a.size(); ++i) {
    if (!(std::isnan(a[i]) && std::isnan(b[i])) && std::memcmp(&a[i], &b[i], sizeof(float)) != 0) {
      return false;
    }
  }
  return true;
}

/// Every buffer, the layout and the viewpoint; @p exact_nan demands bitwise NaNs (binary
/// encodings).
inline bool same_cloud(const orthoflow::kernels::PointCloud& a,
                       const orthoflow::kernels::PointCloud& b, bool exact_nan) {
  auto same = [exact_nan](std::span<const float> u, std::span<const float> v) {
    return exact_nan ? same_bits(u, v) : same_value(u, v);
  };
  const auto& va = a.info.viewpoint;
  const auto& vb = b.info.viewpoint;
  return a.width() == b.width() && a.height() == b.height() && same(a.x(), b.x()) &&
         same(a.y(), b.y()) && same(a.z(), b.z()) && same_bits(a.rgb(), b.rgb()) &&
         same_bits(a.label(), b.label()) && same(a.normal_x(), b.normal_x()) &&
         same(a.normal_y(), b.normal_y()) && same(a.normal_z(), b.normal_z()) &&
         same_value(va.origin, vb.origin) && same_value(va.orientation, vb.orientation);
}

/// Text round trips cost ~1 us per value under ASan; above this many points only the binary
/// encodings are checked, which keeps the fuzzer fast on the large shared seeds (small inputs still
/// cover ascii).
constexpr std::size_t MAX_ASCII_CHECK_POINTS = 512;

/// Writes @p cloud in every PCD encoding, reads it back and traps unless the result is identical.
inline void check_pcd_round_trip(const orthoflow::kernels::PointCloud& cloud) {
  namespace ofmt = orthoflow::formats;
  for (const auto encoding : {ofmt::PcdEncoding::BINARY_COMPRESSED, ofmt::PcdEncoding::BINARY,
                              ofmt::PcdEncoding::ASCII}) {
    if (encoding == ofmt::PcdEncoding::ASCII && cloud.size() > MAX_ASCII_CHECK_POINTS) { continue; }
    const std::string bytes = ofmt::encode_pcd(cloud, encoding);
    auto again = ofmt::read_pcd_buffer(bytes, "fuzz-again");
    if (!again || !same_cloud(cloud, *again, encoding != ofmt::PcdEncoding::ASCII)) {
      __builtin_trap();
    }
  }
}

}  // namespace orthoflow_fuzz
