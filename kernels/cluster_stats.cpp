#include "kernels/cluster_stats.hpp"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <limits>

#include "core/assert.hpp"

namespace orthoflow::kernels {

namespace {

/// Centroid, covariance and PCA axes from the accumulated moments (population covariance).
void finish_moments(const ClusterMoments& m, ClusterStats& s) {
  const double n = static_cast<double>(s.points);
  const Eigen::Vector3d mean_rel = Eigen::Vector3d(m.sum[0], m.sum[1], m.sum[2]) / n;
  Eigen::Matrix3d outer;
  outer << m.outer[0], m.outer[1], m.outer[2], m.outer[1], m.outer[3], m.outer[4], m.outer[2],
      m.outer[4], m.outer[5];
  const Eigen::Matrix3d cov = outer / n - mean_rel * mean_rel.transpose();
  for (std::size_t a = 0; a < 3; ++a) {
    s.centroid[a] = static_cast<float>(mean_rel[static_cast<Eigen::Index>(a)] + m.ref[a]);
  }
  s.covariance = {static_cast<float>(cov(0, 0)), static_cast<float>(cov(0, 1)),
                  static_cast<float>(cov(0, 2)), static_cast<float>(cov(1, 1)),
                  static_cast<float>(cov(1, 2)), static_cast<float>(cov(2, 2))};
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> solver;
  solver.computeDirect(cov);  // ascending eigenvalues
  Eigen::Matrix3d axes;
  axes.row(0) = solver.eigenvectors().col(2).transpose();
  axes.row(1) = solver.eigenvectors().col(1).transpose();
  axes.row(2) = axes.row(0).cross(axes.row(1));
  for (Eigen::Index r = 0; r < 3; ++r) {
    for (Eigen::Index c = 0; c < 3; ++c) {
      s.obb_axes[static_cast<std::size_t>(3 * r + c)] = static_cast<float>(axes(r, c));
    }
  }
}

/// The first index >= i below n with a label >= 0, or n. Most pixels of a frame are unlabelled:
/// eight labels are all negative exactly when the AND of their sign bits is set, one test for
/// eight.
std::size_t skip_unlabelled(std::span<const std::int32_t> labels, std::size_t i, std::size_t n) {
  while (i + 8 <= n && (labels[i] & labels[i + 1] & labels[i + 2] & labels[i + 3] & labels[i + 4] &
                        labels[i + 5] & labels[i + 6] & labels[i + 7]) < 0) {
    i += 8;
  }
  while (i < n && labels[i] < 0) { ++i; }
  return i;
}

/// Calls visit(i) for every labelled index i, ascending: from @p list when @p listed (entries with
/// a negative label are skipped), else by scanning all n labels.
template <class Visit>
void for_labelled(std::span<const std::int32_t> labels, std::span<const std::uint32_t> list,
                  bool listed, std::size_t n, Visit visit) {
  if (listed) {
    for (const std::uint32_t i : list) {
      if (labels[i] >= 0) { visit(std::size_t{i}); }
    }
    return;
  }
  for (std::size_t i = 0; i < n; ++i) {
    if (labels[i] < 0 && (i = skip_unlabelled(labels, i, n)) == n) { break; }
    visit(i);
  }
}

/// One cluster's pass-1/2 accumulators held in registers over a run of equal labels (consecutive
/// labelled pixels mostly share a label): the same additions in the same order as updating the
/// arrays point by point, without a store-to-load round trip per point.
struct RunAccumulator {
  std::size_t points = 0;
  std::array<float, 3> lo{}, hi{};
  ClusterMoments m;
  void load(const ClusterStats& s, const ClusterMoments& mom) {
    points = s.points, lo = s.bbox_min, hi = s.bbox_max, m = mom;
  }
  void store(ClusterStats& s, ClusterMoments& mom) const {
    s.points = points, s.bbox_min = lo, s.bbox_max = hi, mom = m;
  }
  void add(const std::array<float, 3>& p) {
    if (points++ == 0) { m.ref = {p[0], p[1], p[2]}; }
    for (std::size_t a = 0; a < 3; ++a) {
      lo[a] = std::min(lo[a], p[a]);
      hi[a] = std::max(hi[a], p[a]);
    }
    const double q[3] = {p[0] - m.ref[0], p[1] - m.ref[1], p[2] - m.ref[2]};
    for (std::size_t a = 0; a < 3; ++a) { m.sum[a] += q[a]; }
    m.outer[0] += q[0] * q[0];
    m.outer[1] += q[0] * q[1];
    m.outer[2] += q[0] * q[2];
    m.outer[3] += q[1] * q[1];
    m.outer[4] += q[1] * q[2];
    m.outer[5] += q[2] * q[2];
  }
};

/// Passes 1 and 2: counts, boxes, reference points and the moments around the reference.
void accumulate(PointsView points, std::span<const std::int32_t> labels,
                std::span<const std::uint32_t> list, bool listed, std::span<ClusterMoments> moments,
                std::span<ClusterStats> out) {
  constexpr std::size_t NONE = std::numeric_limits<std::size_t>::max();
  std::size_t cur = NONE;
  RunAccumulator acc;
  for_labelled(labels, list, listed, points.size(), [&](std::size_t i) {
    const auto c = static_cast<std::size_t>(labels[i]);
    if (c != cur) {
      if (cur != NONE) { acc.store(out[cur], moments[cur]); }
      cur = c;
      acc.load(out[c], moments[c]);
    }
    acc.add({points.x[i], points.y[i], points.z[i]});
  });
  if (cur != NONE) { acc.store(out[cur], moments[cur]); }
}

/// Pass 3: extents in the PCA frame around the centroid, a run of equal labels in registers.
void extents(PointsView points, std::span<const std::int32_t> labels,
             std::span<const std::uint32_t> list, bool listed, std::span<ClusterStats> out) {
  constexpr std::size_t NONE = std::numeric_limits<std::size_t>::max();
  std::size_t cur = NONE;
  ClusterStats s;
  for_labelled(labels, list, listed, points.size(), [&](std::size_t i) {
    const auto c = static_cast<std::size_t>(labels[i]);
    if (c != cur) {
      if (cur != NONE) { out[cur].obb_min = s.obb_min, out[cur].obb_max = s.obb_max; }
      cur = c;
      s = out[c];
    }
    const float q[3] = {points.x[i] - s.centroid[0], points.y[i] - s.centroid[1],
                        points.z[i] - s.centroid[2]};
    for (std::size_t r = 0; r < 3; ++r) {
      const float t =
          s.obb_axes[3 * r] * q[0] + s.obb_axes[3 * r + 1] * q[1] + s.obb_axes[3 * r + 2] * q[2];
      s.obb_min[r] = std::min(s.obb_min[r], t);
      s.obb_max[r] = std::max(s.obb_max[r], t);
    }
  });
  if (cur != NONE) { out[cur].obb_min = s.obb_min, out[cur].obb_max = s.obb_max; }
}

std::size_t stats_impl(PointsView points, std::span<const std::int32_t> labels,
                       std::span<const std::uint32_t> list, bool listed,
                       std::span<ClusterMoments> moments, std::span<ClusterStats> out) {
  OF_ASSERT(moments.size() >= out.size() && labels.size() >= points.size(),
            "cluster_stats: spans too small");
  const float inf = std::numeric_limits<float>::infinity();
  for (std::size_t c = 0; c < out.size(); ++c) {
    out[c] = ClusterStats{};
    out[c].bbox_min = out[c].obb_min = {inf, inf, inf};
    out[c].bbox_max = out[c].obb_max = {-inf, -inf, -inf};
    moments[c] = ClusterMoments{};
  }
  accumulate(points, labels, list, listed, moments, out);
  for (std::size_t c = 0; c < out.size(); ++c) {
    if (out[c].points == 0) {
      out[c] = ClusterStats{};
    } else {
      finish_moments(moments[c], out[c]);
    }
  }
  extents(points, labels, list, listed, out);
  return out.size();
}

}  // namespace

std::size_t cluster_stats(PointsView points, std::span<const std::int32_t> labels,
                          std::span<ClusterMoments> moments, std::span<ClusterStats> out) noexcept {
  return stats_impl(points, labels, {}, false, moments, out);
}

std::size_t cluster_stats_listed(PointsView points, std::span<const std::int32_t> labels,
                                 std::span<const std::uint32_t> members,
                                 std::span<ClusterMoments> moments,
                                 std::span<ClusterStats> out) noexcept {
  return stats_impl(points, labels, members, true, moments, out);
}

}  // namespace orthoflow::kernels
