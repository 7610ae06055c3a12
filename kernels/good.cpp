#include "kernels/good.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <new>

#include "kernels/detail/good_kernel.hpp"
#include "kernels/detail/good_order.hpp"
#include "kernels/far_points.hpp"

namespace orthoflow::kernels {

namespace {

using detail::GoodStats;
using detail::GoodTransform;

GoodTransform make_transform(const PcaFrame& f, const std::array<int, 3>& signs) noexcept {
  GoodTransform t;
  for (std::size_t a = 0; a < 3; ++a) {
    t.c[a] = static_cast<float>(f.centroid[a]);
    for (std::size_t k = 0; k < 3; ++k) { t.r[a][k] = static_cast<float>(signs[a] * f.axes[a][k]); }
  }
  return t;
}

// Third central moment sum q^3 and second sum q^2 along one provisional axis, in double.
std::array<double, 2> moments_along(PointsView points, const PcaFrame& f,
                                    std::size_t axis) noexcept {
  std::array<double, 2> m{0.0, 0.0};
  for (std::size_t i = 0; i < points.size(); ++i) {
    const double d[3] = {points.x[i] - f.centroid[0], points.y[i] - f.centroid[1],
                         points.z[i] - f.centroid[2]};
    const double q = f.axes[axis][0] * d[0] + f.axes[axis][1] * d[1] + f.axes[axis][2] * d[2];
    if (!std::isfinite(q)) { continue; }
    m[0] += q * q;
    m[1] += q * q * q;
  }
  return m;
}

// Invariant sign of a provisional axis (docs/GOOD.md, "tie rule"). Every rule reads only the shape
// in the provisional frame, and flipping the axis flips each statistic, so the chosen direction is
// pose-free:
// 1. counts beyond +-t: the side with more points wins if it leads by more than 1 % of the points;
// 2. else the sign of the third moment (skewness), if |skew| > 1e-3;
// 3. else the side that reaches farther from the centroid, if it is farther by > 1e-4 of the
// extent;
// 4. else +1 and SIGN_AMBIGUOUS (the shape is symmetric along the axis: both signs look alike).
int invariant_sign(PointsView points, const PcaFrame& f, const GoodStats& s, std::size_t axis,
                   std::uint32_t& flags) noexcept {
  const std::size_t margin = f.finite / 100;
  if (s.pos[axis] > s.neg[axis] + margin) { return 1; }
  if (s.neg[axis] > s.pos[axis] + margin) { return -1; }
  const std::array<double, 2> m = moments_along(points, f, axis);
  const double count = static_cast<double>(f.finite);
  const double sigma3 = std::pow(m[0] / count, 1.5);
  if (std::abs(m[1] / count) > 1e-3 * sigma3) { return m[1] > 0.0 ? 1 : -1; }
  const double reach = static_cast<double>(s.max[axis]) + static_cast<double>(s.min[axis]);
  const double extent = static_cast<double>(s.max[axis]) - static_cast<double>(s.min[axis]);
  if (std::abs(reach) > 1e-4 * extent) { return reach > 0.0 ? 1 : -1; }
  flags |= SIGN_AMBIGUOUS;
  return 1;
}

// Reference rule (GOOD_REFERENCE.md section 4): flip only if neg > pos and neg - pos >=
// floor(m/10), m counting every input point, NaN included.
int reference_sign(const GoodStats& s, std::size_t axis, std::size_t all_points) noexcept {
  const std::size_t margin = all_points / 10;
  return (s.neg[axis] > s.pos[axis] && s.neg[axis] - s.pos[axis] >= margin) ? -1 : 1;
}

std::array<float, 16> frame_matrix(const GoodTransform& t) noexcept {
  std::array<float, 16> m{};
  for (std::size_t a = 0; a < 3; ++a) {
    double tr = 0.0;
    for (std::size_t k = 0; k < 3; ++k) {
      m[a * 4 + k] = t.r[a][k];
      tr -= static_cast<double>(t.r[a][k]) * static_cast<double>(t.c[k]);
    }
    m[a * 4 + 3] = static_cast<float>(tr);
  }
  m[15] = 1.0F;
  return m;
}

std::optional<GoodError> validate(PointsView points, const GoodConfig& cfg,
                                  const GoodScratch& scratch, std::span<float> out) noexcept {
  const float t = cfg.effective_threshold();
  if (cfg.bins == 0 || cfg.bins > GOOD_MAX_BINS) { return GoodError::BAD_BINS; }
  if (!std::isfinite(t) || t < 0.0F) { return GoodError::BAD_THRESHOLD; }
  if (scratch.max_bins() < cfg.bins) { return GoodError::SCRATCH_TOO_SMALL; }
  if (out.size() < 3 * cfg.bins * cfg.bins) { return GoodError::OUTPUT_TOO_SMALL; }
  if (points.empty()) { return GoodError::EMPTY_CLOUD; }
  return std::nullopt;
}

std::array<int, 3> choose_signs(PointsView points, const GoodConfig& cfg, const PcaFrame& f,
                                const GoodStats& s, std::uint32_t& flags) noexcept {
  if (cfg.mode == GoodMode::INVARIANT) {
    const int sx = invariant_sign(points, f, s, 0, flags);
    const int sy = invariant_sign(points, f, s, 1, flags);
    return {sx, sy, sx * sy};  // Z = X x Y = (Sx v1) x (Sy v2) = Sx Sy v3
  }
  const int sign = reference_sign(s, 0, points.size()) * reference_sign(s, 1, points.size());
  return {sign, sign, 1};  // s multiplies x and y only; z is never flipped
}

template <class FrameFn, class StatsFn, class BinFn>
Result<GoodResult, GoodError> run_good(PointsView all_points, const GoodConfig& cfg,
                                       GoodScratch& scratch, std::span<float> out,
                                       FrameFn&& frame_fn, StatsFn&& stats_fn,
                                       BinFn&& bin_fn) noexcept {
  if (const auto bad = validate(all_points, cfg, scratch, out)) { return err(*bad); }
  const FarPoints far = find_far_points(all_points);
  PointsView points = all_points;
  if (far.count > 0) {
    const PointsSpan near = scratch.near_points(all_points.size() - far.count);
    if (near.size() != all_points.size() - far.count) { return err(GoodError::OUT_OF_MEMORY); }
    copy_near_points(all_points, far, near);
    points = near;
  }
  const auto frame_result = frame_fn(points);
  if (!frame_result) { return err(GoodError::NO_FINITE_POINTS); }
  const PcaFrame& f = frame_result.value();
  GoodResult r;
  r.flags = f.flags;
  const GoodStats s = stats_fn(points, make_transform(f, {1, 1, 1}), cfg.effective_threshold());
  r.signs = choose_signs(points, cfg, f, s, r.flags);
  detail::GoodBinParams p;
  p.t = make_transform(f, r.signs);
  p.bins = cfg.bins;
  for (std::size_t a = 0; a < 3; ++a) { r.bbox[a] = s.max[a] - s.min[a]; }
  // L = largest edge + 0.02 m in double, square centred on the centroid (section 5).
  const double side =
      static_cast<double>(std::max({r.bbox[0], r.bbox[1], r.bbox[2]})) + GOOD_SQUARE_MARGIN;
  p.half = static_cast<float>(side / 2.0);
  p.width = static_cast<float>(side / static_cast<double>(cfg.bins));
  const std::size_t len = 3 * cfg.bins * cfg.bins;
  const std::span<std::uint32_t> counts = scratch.buffer().subspan(0, len + 3);  // + 3 drop slots
  std::fill(counts.begin(), counts.end(), 0U);
  bin_fn(points, p, counts);
  for (std::size_t v = 0; v < 3; ++v) { r.kept[v] = points.size() - counts[len + v]; }
  const detail::GoodOrderOut o =
      detail::good_normalise_and_order(counts, r.kept, cfg.bins, out.subspan(0, len));
  r.length = len;
  r.frame = frame_matrix(p.t);
  r.order = o.order;
  r.entropy = o.entropy;
  r.variance = o.variance;
  for (std::size_t a = 0; a < 3; ++a) { r.eigenvalues[a] = static_cast<float>(f.eigenvalues[a]); }
  r.side = static_cast<float>(side);
  r.points_used = f.finite;
  r.far_points = far.count;
  if (o.empty_view) { r.flags |= EMPTY_VIEW; }
  if (far.count > 0) { r.flags |= FAR_POINTS_DROPPED; }
  return r;
}

}  // namespace

const char* to_string(GoodView view) noexcept {
  switch (view) {
    case GoodView::YOZ:
      return "YoZ";
    case GoodView::XOZ:
      return "XoZ";
    case GoodView::XOY:
      return "XoY";
  }
  return "?";
}

const char* to_string(GoodError error) noexcept {
  switch (error) {
    case GoodError::EMPTY_CLOUD:
      return "compute_good: the cloud has no points";
    case GoodError::NO_FINITE_POINTS:
      return "compute_good: every point has a NaN or infinite coordinate";
    case GoodError::BAD_BINS:
      return "compute_good: config.bins must be between 1 and 256";
    case GoodError::BAD_THRESHOLD:
      return "compute_good: config.threshold must be finite and >= 0";
    case GoodError::OUTPUT_TOO_SMALL:
      return "compute_good: descriptor_out holds fewer than 3*bins*bins values";
    case GoodError::SCRATCH_TOO_SMALL:
      return "compute_good: the GoodScratch was made for fewer bins than requested";
    case GoodError::OUT_OF_MEMORY:
      return "compute_good: out of memory for a copy of the view without its far points";
    case GoodError::KEYPOINTS_FAILED:
      return "bag of words: the keypoints' voxel grid refused the view (too wide for its leaf)";
    case GoodError::NO_FEATURES:
      return "bag of words: no spin image of the view has weight (too few points within the "
             "support length)";
    case GoodError::TOO_MANY_POINTS:
      return "bag of words: the view has more points than the describer's scratch was reserved for";
  }
  return "compute_good: unknown error";
}

PointsSpan GoodScratch::near_points(std::size_t n) noexcept {
  try {
    if (near_.size() < 3 * n) { near_.resize(3 * n); }
  } catch (const std::bad_alloc&) { return {}; }
  const std::span<float> all(near_);
  return {all.subspan(0, n), all.subspan(n, n), all.subspan(2 * n, n)};
}

Result<GoodResult, GoodError> compute_good_scalar(PointsView points, const GoodConfig& cfg,
                                                  GoodScratch& scratch,
                                                  std::span<float> descriptor_out) noexcept {
  const auto stats = [](PointsView pts, const GoodTransform& t, float thr) {
    const float inf = std::numeric_limits<float>::infinity();
    GoodStats s{{inf, inf, inf}, {-inf, -inf, -inf}, {0, 0}, {0, 0}};
    detail::good_stats_scalar(pts, t, thr, 0, pts.size(), s);
    return s;
  };
  const auto bins = [](PointsView pts, const detail::GoodBinParams& p, std::span<std::uint32_t> c) {
    detail::good_bin_range_scalar(pts, p, 0, pts.size(), c);
  };
  return run_good(points, cfg, scratch, descriptor_out, compute_pca_frame_scalar, stats, bins);
}

Result<GoodResult, GoodError> compute_good(PointsView points, const GoodConfig& cfg,
                                           GoodScratch& scratch,
                                           std::span<float> descriptor_out) noexcept {
  static auto stats = xsimd::dispatch<SimdArchs>(detail::GoodStatsKernel{});
  static auto bins = xsimd::dispatch<SimdArchs>(detail::GoodBinKernel{});
  return run_good(points, cfg, scratch, descriptor_out, compute_pca_frame, stats, bins);
}

}  // namespace orthoflow::kernels
