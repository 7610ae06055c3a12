#include "kernels/pinhole_regrid.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

namespace orthoflow::kernels {

namespace {

constexpr std::size_t MAX_PITCH_SAMPLES = 8192;
constexpr double SAME_ROW = 1e-6;   // |delta y/z| below this: consecutive points of one row
constexpr double MIN_PITCH = 1e-5;  // 1 / fx for fx up to 100,000 px: smaller steps are noise

/// One axis of the grid: value = pitch * k + offset for integer k.
struct Axis {
  double pitch = 0.0, offset = 0.0;
  std::int64_t k_min = 0, k_max = 0;
  double max_residual = 0.0;  // pixels
};

double median(std::vector<double>& v) {
  const auto mid = v.begin() + static_cast<std::ptrdiff_t>(v.size() / 2);
  std::nth_element(v.begin(), mid, v.end());
  return *mid;
}

/// Refines @p axis's pitch and offset by least squares of @p values against their rounded grid
/// index (twice), then measures the residuals and the index range.
void fit(const std::vector<double>& values, Axis& axis) {
  const double origin = values.front();
  for (int round = 0; round < 2; ++round) {
    double sk = 0, sv = 0, skk = 0, skv = 0;
    for (const double v : values) {
      const double k = std::round((v - origin - axis.offset) / axis.pitch);
      sk += k;
      sv += v - origin;
      skk += k * k;
      skv += k * (v - origin);
    }
    const double n = static_cast<double>(values.size()), det = n * skk - sk * sk;
    if (det <= 0.0) return;  // a single column or row: keep the estimate
    axis.pitch = (n * skv - sk * sv) / det;
    axis.offset = (sv - axis.pitch * sk) / n;
  }
  axis.offset += origin;
  axis.k_min = std::numeric_limits<std::int64_t>::max();
  axis.k_max = std::numeric_limits<std::int64_t>::min();
  axis.max_residual = 0.0;
  for (const double v : values) {
    const double u = (v - axis.offset) / axis.pitch, k = std::round(u);
    axis.max_residual = std::max(axis.max_residual, std::fabs(u - k));
    axis.k_min = std::min(axis.k_min, static_cast<std::int64_t>(k));
    axis.k_max = std::max(axis.k_max, static_cast<std::int64_t>(k));
  }
}

/// The pitch of steps that are whole multiples of it (consecutive points of one row skip the
/// columns of dropped pixels; a row change skips the rows without a point): the direction of most
/// steps, then the smallest step size that many steps share (within a relative 1e-3; at least
/// 1/20 of them and 8), so that a few points off the grid cannot pass for a finer pitch. 0: none.
double pitch_of(std::vector<double>& steps) {
  if (steps.empty()) return 0.0;
  const double sign = median(steps) > 0.0 ? 1.0 : -1.0;
  std::vector<double> magnitudes;
  magnitudes.reserve(steps.size());
  for (const double s : steps)
    if (s * sign > MIN_PITCH) magnitudes.push_back(s * sign);
  std::sort(magnitudes.begin(), magnitudes.end());
  const std::size_t enough = std::max<std::size_t>(8, magnitudes.size() / 20);
  for (std::size_t i = 0; i < magnitudes.size();) {
    std::size_t j = i;
    while (j < magnitudes.size() && magnitudes[j] <= magnitudes[i] * (1.0 + 1e-3)) ++j;
    if (j - i >= enough) return sign * magnitudes[i + (j - i) / 2];
    i = j;
  }
  return 0.0;
}

}  // namespace

std::string_view to_string(GridRefusal refusal) noexcept {
  switch (refusal) {
    case GridRefusal::TOO_FEW_POINTS:
      return "too few finite points";
    case GridRefusal::NO_PITCH:
      return "no row of consecutive pixels in the stored order";
    case GridRefusal::OFF_GRID:
      return "points off any pixel grid (not a camera-frame pinhole image)";
    case GridRefusal::TOO_LARGE:
      return "grid larger than 4096 pixels";
    case GridRefusal::SHARED_PIXEL:
      return "two points on one pixel";
  }
  return "unknown";
}

Result<PinholeGrid, GridRefusal> find_pinhole_grid(PointsView cloud) {
  std::vector<double> a, b;  // x / z and y / z of the finite points in front, in stored order
  a.reserve(cloud.size());
  b.reserve(cloud.size());
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    const float x = cloud.x[i], y = cloud.y[i], z = cloud.z[i];
    if (!std::isfinite(x) || !std::isfinite(y) || !std::isfinite(z) || !(z > 0.0F)) continue;
    a.push_back(static_cast<double>(x) / z);
    b.push_back(static_cast<double>(y) / z);
  }
  if (a.size() < MIN_GRID_POINTS) return err(GridRefusal::TOO_FEW_POINTS);
  // Pitches from the stored order: every row change, and the column steps sampled evenly.
  std::vector<double> column_steps, row_steps;
  const std::size_t stride = std::max<std::size_t>(1, a.size() / MAX_PITCH_SAMPLES);
  std::size_t same_row = 0;
  for (std::size_t i = 0; i + 1 < a.size(); ++i) {
    const double db = b[i + 1] - b[i];
    if (std::fabs(db) >= SAME_ROW) {
      if (row_steps.size() < MAX_PITCH_SAMPLES) row_steps.push_back(db);
      continue;
    }
    ++same_row;
    if (i % stride == 0) column_steps.push_back(a[i + 1] - a[i]);
  }
  // Most consecutive pairs must be points of one row, or the order says nothing about the grid.
  if (column_steps.size() < 16 || row_steps.empty() || same_row * 2 < a.size())
    return err(GridRefusal::NO_PITCH);
  Axis u, v;
  u.pitch = pitch_of(column_steps);
  v.pitch = pitch_of(row_steps);
  if (!(std::fabs(u.pitch) > MIN_PITCH) || !(std::fabs(v.pitch) > MIN_PITCH))
    return err(GridRefusal::NO_PITCH);
  fit(a, u);
  fit(b, v);
  if (u.max_residual > MAX_RESIDUAL_PX || v.max_residual > MAX_RESIDUAL_PX)
    return err(GridRefusal::OFF_GRID);
  const std::int64_t width = u.k_max - u.k_min + 1, height = v.k_max - v.k_min + 1;
  if (width > MAX_GRID_SIDE || height > MAX_GRID_SIDE) return err(GridRefusal::TOO_LARGE);
  if (static_cast<std::size_t>(width * height) < a.size()) return err(GridRefusal::SHARED_PIXEL);
  PinholeGrid g;
  g.fx = 1.0 / u.pitch;
  g.fy = 1.0 / v.pitch;
  g.cx = -u.offset / u.pitch - static_cast<double>(u.k_min);
  g.cy = -v.offset / v.pitch - static_cast<double>(v.k_min);
  g.width = static_cast<std::uint32_t>(width);
  g.height = static_cast<std::uint32_t>(height);
  g.max_residual_px = std::max(u.max_residual, v.max_residual);
  // No two points on one pixel.
  std::vector<bool> taken(static_cast<std::size_t>(width * height), false);
  for (std::size_t i = 0; i < a.size(); ++i) {
    const auto col = static_cast<std::size_t>(std::llround(g.fx * a[i] + g.cx));
    const auto row = static_cast<std::size_t>(std::llround(g.fy * b[i] + g.cy));
    const std::size_t cell = row * g.width + col;
    if (taken[cell]) return err(GridRefusal::SHARED_PIXEL);
    taken[cell] = true;
  }
  return g;
}

void regrid(const PointCloud& in, const PinholeGrid& grid, PointCloud& out) {
  out.remove_field(Field::NORMALS);
  const bool rgb = in.has(Field::RGB), label = in.has(Field::LABEL);
  rgb ? out.add_field(Field::RGB) : out.remove_field(Field::RGB);
  label ? out.add_field(Field::LABEL) : out.remove_field(Field::LABEL);
  out.resize(grid.width, grid.height);
  const float nan = std::numeric_limits<float>::quiet_NaN();
  std::fill(out.x().begin(), out.x().end(), nan);
  std::fill(out.y().begin(), out.y().end(), nan);
  std::fill(out.z().begin(), out.z().end(), nan);
  if (rgb) std::fill(out.rgb().begin(), out.rgb().end(), 0U);
  if (label) std::fill(out.label().begin(), out.label().end(), 0U);
  const PointsView p = in.points();
  for (std::size_t i = 0; i < p.size(); ++i) {
    const float x = p.x[i], y = p.y[i], z = p.z[i];
    if (!std::isfinite(x) || !std::isfinite(y) || !std::isfinite(z) || !(z > 0.0F)) continue;
    const auto col = std::llround(grid.fx * (static_cast<double>(x) / z) + grid.cx);
    const auto row = std::llround(grid.fy * (static_cast<double>(y) / z) + grid.cy);
    const std::size_t cell =
        static_cast<std::size_t>(row) * grid.width + static_cast<std::size_t>(col);
    out.x()[cell] = x;
    out.y()[cell] = y;
    out.z()[cell] = z;
    if (rgb) out.rgb()[cell] = in.rgb()[i];
    if (label) out.label()[cell] = in.label()[i];
  }
  out.info = in.info;
}

Result<PinholeGrid, GridRefusal> organize_if_pinhole(PointCloud& cloud, std::size_t max_points) {
  if (cloud.organized()) {
    PinholeGrid g;
    g.width = cloud.width();
    g.height = cloud.height();
    return g;
  }
  auto grid = find_pinhole_grid(cloud.points());
  if (!grid) return grid;
  if (std::size_t{grid->width} * grid->height > max_points) return err(GridRefusal::TOO_LARGE);
  PointCloud organized;
  regrid(cloud, *grid, organized);
  cloud = std::move(organized);
  return grid;
}

}  // namespace orthoflow::kernels
