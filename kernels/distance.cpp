#include "kernels/distance.hpp"

#include <cmath>

#include "core/assert.hpp"
#include "kernels/detail/distance_kernel.hpp"

namespace orthoflow::kernels {

namespace {

void check_shapes(std::span<const float> query, const DescriptorMatrixView& s,
                  std::size_t out_size) noexcept {
  OF_ENFORCE(query.size() == s.dims,
             "distances: query length differs from the stored descriptors' dims");
  OF_ENFORCE(s.stride >= s.count, "distances: stored.stride is smaller than stored.count");
  OF_ENFORCE(s.count == 0 || s.dims == 0 || s.data.size() >= (s.dims - 1) * s.stride + s.count,
             "distances: stored.data is shorter than (dims - 1) * stride + count");
  OF_ENFORCE(out_size >= s.count, "distances: the output holds fewer values than stored.count");
}

// NaN ranks after every number; equal distances keep the lower index first (deterministic order).
bool before(float da, std::size_t ia, float db, std::size_t ib) noexcept {
  const bool na = std::isnan(da);
  const bool nb = std::isnan(db);
  if (na != nb) { return nb; }
  if (!na && da != db) { return da < db; }
  return ia < ib;
}

// Bounded insertion into the sorted out[0..filled): O(count) when k is small, as in recognition.
std::size_t select_k(std::span<const float> dist, std::size_t count,
                     std::span<Neighbor> out) noexcept {
  const std::size_t k = out.size();
  std::size_t filled = 0;
  for (std::size_t j = 0; j < count && k > 0; ++j) {
    if (filled == k && !before(dist[j], j, out[k - 1].distance, out[k - 1].index)) { continue; }
    std::size_t pos = filled < k ? filled++ : k - 1;
    while (pos > 0 && before(dist[j], j, out[pos - 1].distance, out[pos - 1].index)) {
      out[pos] = out[pos - 1];
      --pos;
    }
    out[pos] = Neighbor{j, dist[j]};
  }
  return filled;
}

}  // namespace

const char* to_string(Metric metric) noexcept {
  switch (metric) {
    case Metric::L1:
      return "l1";
    case Metric::L2:
      return "l2";
    case Metric::L2_SQUARED:
      return "l2_squared";
    case Metric::CHI_SQUARED:
      return "chi_squared";
    case Metric::SYMMETRIC_KL:
      return "symmetric_kl";
    case Metric::JENSEN_SHANNON:
      return "jensen_shannon";
  }
  return "unknown";
}

std::size_t distances_scalar(std::span<const float> query, DescriptorMatrixView stored,
                             Metric metric, std::span<float> out) noexcept {
  check_shapes(query, stored, out.size());
  detail::distance_columns_scalar(query, stored, metric, 0, stored.count, out);
  return stored.count;
}

std::size_t distances(std::span<const float> query, DescriptorMatrixView stored, Metric metric,
                      std::span<float> out) noexcept {
  check_shapes(query, stored, out.size());
  static auto dispatched = xsimd::dispatch<SimdArchs>(detail::DistanceKernel{});
  dispatched(query, stored, metric, out);
  return stored.count;
}

std::size_t nearest_k(std::span<const float> query, DescriptorMatrixView stored, Metric metric,
                      std::span<float> scratch, std::span<Neighbor> out) noexcept {
  const std::size_t n = distances(query, stored, metric, scratch);
  return select_k(scratch, n, out);
}

std::size_t nearest_k_scalar(std::span<const float> query, DescriptorMatrixView stored,
                             Metric metric, std::span<float> scratch,
                             std::span<Neighbor> out) noexcept {
  const std::size_t n = distances_scalar(query, stored, metric, scratch);
  return select_k(scratch, n, out);
}

}  // namespace orthoflow::kernels
