#include "kernels/object_candidates.hpp"

#include <algorithm>
#include <array>
#include <cmath>

namespace orthoflow::kernels {

double inside_distance(double u, double v, std::span<const double> hu,
                       std::span<const double> hv) noexcept {
  double best = 1e300;
  const std::size_t n = std::min(hu.size(), hv.size());
  for (std::size_t k = 0; k < n; ++k) {
    const std::size_t j = (k + 1) % n;
    const double ex = hu[j] - hu[k], ey = hv[j] - hv[k];
    const double len = std::hypot(ex, ey);
    if (len == 0.0) continue;
    best = std::min(
        best, (ex * (v - hv[k]) - ey * (u - hu[k])) / len);  // counter-clockwise: left is inside
  }
  return best;
}

namespace {

constexpr std::int32_t OVER = -2;  // passed both constraints, found the candidates full

float range2(const ClusterStats& st) noexcept {
  return st.centroid[0] * st.centroid[0] + st.centroid[1] * st.centroid[1] +
         st.centroid[2] * st.centroid[2];
}

/// Swaps each candidate left over for the farthest kept one while it is nearer (ties: the lower
/// cluster index is nearer), then numbers the kept ones in cluster order again; the rest get -1.
void keep_nearest(std::span<const ClusterStats> clusters, std::span<std::int32_t> slot_of) {
  auto nearer = [&](std::size_t a, std::size_t b) {
    const float ra = range2(clusters[a]), rb = range2(clusters[b]);
    return ra < rb || (ra == rb && a < b);
  };
  for (std::size_t c = 0; c < clusters.size(); ++c) {
    if (slot_of[c] != OVER) continue;
    std::size_t far = clusters.size();
    for (std::size_t k = 0; k < clusters.size(); ++k) {
      if (slot_of[k] >= 0 && (far == clusters.size() || nearer(far, k))) far = k;
    }
    if (far < clusters.size() && nearer(c, far)) std::swap(slot_of[c], slot_of[far]);
  }
  std::int32_t next = 0;
  for (auto& slot : slot_of) slot = slot >= 0 ? next++ : -1;
}

}  // namespace

CandidateCounts select_candidates(std::span<const ClusterStats> clusters, const Plane& plane,
                                  std::span<const double> hu, std::span<const double> hv,
                                  const CandidateParams& p, std::size_t max_candidates,
                                  std::span<std::int32_t> slot_of) noexcept {
  CandidateCounts counts;
  const PlaneBasis basis = make_plane_basis(plane);
  for (std::size_t c = 0; c < clusters.size(); ++c) {
    slot_of[c] = -1;
    const ClusterStats& st = clusters[c];
    float largest = 0.0F;
    for (std::size_t a = 0; a < 3; ++a) largest = std::max(largest, st.obb_max[a] - st.obb_min[a]);
    if (st.points == 0 || largest < p.min_size || largest > p.max_size) {
      ++counts.rejected_size;
      continue;
    }
    double u = 0.0, w = 0.0;
    const std::array<std::uint32_t, 1> zero{0};
    const PointsView centroid{{&st.centroid[0], 1}, {&st.centroid[1], 1}, {&st.centroid[2], 1}};
    project_to_plane(centroid, zero, basis, {&u, 1}, {&w, 1});
    if (inside_distance(u, w, hu, hv) < p.edge_margin) {
      ++counts.rejected_edge;
      continue;
    }
    if (counts.kept == max_candidates) {
      ++counts.over_capacity;
      slot_of[c] = OVER;
      continue;
    }
    slot_of[c] = static_cast<std::int32_t>(counts.kept++);
  }
  if (counts.over_capacity > 0) keep_nearest(clusters, slot_of.first(clusters.size()));
  return counts;
}

std::size_t gather_candidates(PointsView target, std::span<const std::int32_t> labels,
                              std::span<const std::uint32_t> members,
                              std::span<const std::int32_t> slot_of,
                              std::span<const std::size_t> sizes, PointsSpan dst,
                              std::span<CandidateSpan> spans, std::span<const std::uint32_t> tags,
                              std::size_t bins, std::span<std::uint32_t> tag_histogram) noexcept {
  std::uint32_t next = 0;
  for (std::size_t k = 0; k < sizes.size(); ++k) {
    spans[k] = CandidateSpan{next, 0};
    next += static_cast<std::uint32_t>(sizes[k]);
  }
  const bool with_tags = !tags.empty() && bins > 0 && tag_histogram.size() >= sizes.size() * bins;
  if (with_tags) std::fill_n(tag_histogram.begin(), sizes.size() * bins, 0U);
  std::size_t written = 0;
  auto visit = [&](std::size_t i) {
    const std::int32_t label = labels[i];
    if (label < 0 || static_cast<std::size_t>(label) >= slot_of.size()) return;
    const std::int32_t slot = slot_of[static_cast<std::size_t>(label)];
    if (slot < 0 || static_cast<std::size_t>(slot) >= sizes.size()) return;
    const auto k = static_cast<std::size_t>(slot);
    CandidateSpan& s = spans[k];
    if (s.count == sizes[k]) return;  // never past the candidate's room
    const std::size_t at = s.first + s.count++;
    dst.x[at] = target.x[i];
    dst.y[at] = target.y[i];
    dst.z[at] = target.z[i];
    if (with_tags && tags[i] < bins) ++tag_histogram[k * bins + tags[i]];
    ++written;
  };
  if (members.empty()) {
    for (std::size_t i = 0; i < target.size(); ++i) visit(i);
  } else {
    for (const std::uint32_t i : members) visit(i);
  }
  return written;
}

std::uint32_t majority_tag(std::span<const std::uint32_t> histogram, std::size_t points) noexcept {
  if (histogram.size() < 2) return 0;
  const auto best = static_cast<std::uint32_t>(
      std::max_element(histogram.begin() + 1, histogram.end()) - histogram.begin());
  return histogram[best] > 0 && std::size_t{histogram[best]} * 2 >= points ? best : 0U;
}

}  // namespace orthoflow::kernels
