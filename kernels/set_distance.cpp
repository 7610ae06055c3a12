#include "kernels/set_distance.hpp"

#include <cmath>
#include <limits>

#include "core/assert.hpp"

namespace orthoflow::kernels {

namespace {

using Rows = std::size_t (*)(std::span<const float>, DescriptorMatrixView, Metric,
                             std::span<float>) noexcept;

float set_distance_with(std::span<const float> u, DescriptorMatrixView v, std::span<float> scratch,
                        Rows rows) noexcept {
  OF_ENFORCE(v.dims > 0 && u.size() % v.dims == 0, "set_distance: U is not whole descriptors");
  OF_ENFORCE(scratch.size() >= v.count, "set_distance: scratch shorter than V");
  const std::size_t nu = u.size() / v.dims;
  if (nu == 0) return 0.0F;
  if (v.count == 0) return std::numeric_limits<float>::infinity();
  // Spare columns up to the stride (when the data and the scratch hold them) are computed too, so
  // the kernel stays in its SIMD body; only the first count are compared.
  DescriptorMatrixView computed = v;
  if (v.stride > v.count && scratch.size() >= v.stride && v.data.size() >= v.dims * v.stride)
    computed.count = v.stride;
  double sum = 0.0;
  for (std::size_t i = 0; i < nu; ++i) {
    rows(u.subspan(i * v.dims, v.dims), computed, Metric::L2, scratch);
    float best = scratch[0];
    for (std::size_t j = 0; j < v.count; ++j) {
      const float d = scratch[j];
      if (std::isnan(d)) return std::numeric_limits<float>::quiet_NaN();
      best = d < best ? d : best;
    }
    sum += best;
  }
  return static_cast<float>(sum / static_cast<double>(nu));
}

}  // namespace

float set_distance(std::span<const float> u, DescriptorMatrixView v,
                   std::span<float> scratch) noexcept {
  return set_distance_with(u, v, scratch, distances);
}

float set_distance_scalar(std::span<const float> u, DescriptorMatrixView v,
                          std::span<float> scratch) noexcept {
  return set_distance_with(u, v, scratch, distances_scalar);
}

}  // namespace orthoflow::kernels
