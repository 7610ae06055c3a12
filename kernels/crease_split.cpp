// ObjectStage's crowded mode (kernels/tabletop_stages.hpp, ClusterMode::CROWDED): Euclidean
// clusters of the prism pixels that do not lie on a concave crease, so that two objects touching
// along a crease (a box on a box, a carton against a tin) come apart while one object's own convex
// edges hold it together; then the crease pixels rejoin the nearest piece beside them. The idea is
// that of locally convex connected patches (Stein et al., CVPR 2014), applied per pixel on the
// organized grid instead of on supervoxels.
#include <algorithm>
#include <array>
#include <cmath>

#include "kernels/tabletop_stages.hpp"

namespace orthoflow::kernels {

namespace {

constexpr std::uint8_t UNATTACHED = 255;
/// Per-pixel normals cost about this many times a pixel of the SIMD row kernel (measured on the
/// scattered wall of tests/support/hostile_frames.hpp; a rough figure: only the choice depends on
/// it).
constexpr std::size_t SCATTERED_RATIO = 8;

struct CreaseTest {
  PointsView p;
  const float *nx, *ny, *nz;
  float cos_max;
  /// Normals at a and b differ by more than the angle and the surface from a to b is concave:
  /// (n_a - n_b) . (x_b - x_a) > 0. False when either normal is missing (NaN compares false).
  [[nodiscard]] bool concave(std::size_t a, std::size_t b) const noexcept {
    const float dot = nx[a] * nx[b] + ny[a] * ny[b] + nz[a] * nz[b];
    if (!(dot < cos_max)) return false;
    const float dx = p.x[b] - p.x[a], dy = p.y[b] - p.y[a], dz = p.z[b] - p.z[a];
    return (nx[a] - nx[b]) * dx + (ny[a] - ny[b]) * dy + (nz[a] - nz[b]) * dz > 0.0F;
  }
};

}  // namespace

Result<std::size_t, ClusterError> ObjectStage::cluster_crowded(
    CloudView cloud, const SegmentationParams& p) noexcept {
  const PointsView pts = cloud.points;
  const std::size_t n = pts.size(), w = cloud.width, h = cloud.height;
  if (n > nx_.size()) return err(ClusterError{ClusterError::Code::SCRATCH_TOO_SMALL, double(n)});
  if (p.crease.normals.offset == 0 || p.crease.gap == 0) {
    return err(ClusterError{ClusterError::Code::BAD_PARAMS, 0.0});
  }
  // Only the rows that hold prism pixels, and those the crease test reads around them, need
  // normals: objects cover a band of the image, not the frame.
  std::size_t first_row = h, last_row = 0, prism = 0;
  for (std::size_t r = 0; r < h; ++r) {
    const auto row = std::span<const std::uint8_t>(mask_).subspan(r * w, w);
    if (std::find(row.begin(), row.end(), std::uint8_t{1}) == row.end()) continue;
    first_row = std::min(first_row, r);
    last_row = r;
    prism += static_cast<std::size_t>(std::count(row.begin(), row.end(), std::uint8_t{1}));
  }
  std::fill(off_crease_.begin(), off_crease_.begin() + static_cast<std::ptrdiff_t>(n), 0);
  const std::size_t g = p.crease.gap;
  const PointsSpan normals{std::span(nx_).first(n), std::span(ny_).first(n),
                           std::span(nz_).first(n)};
  // A few pixels scattered over many rows (plane noise above a wall, a hand's rim): the five
  // normals each one's crease test reads, pixel by pixel, cost less than the band of rows.
  const bool scattered =
      first_row <= last_row && SCATTERED_RATIO * 5 * prism < (last_row - first_row + 1) * w;
  if (first_row > last_row) {
    first_row = last_row = 0;  // no prism pixel: the loop below sees none
  } else if (!scattered) {
    const RowRange rows{static_cast<std::uint32_t>(first_row >= g ? first_row - g : 0),
                        static_cast<std::uint32_t>(std::min(h, last_row + g + 1))};
    // Thinned by the budget to every s-th row, with s dividing the gap: the crease test reads
    // normals only on grid rows (its members' and those g rows away), so only they are computed.
    const std::uint32_t s = p.cluster.pixel_step;
    if (s > 1 && g % s == 0) {
      for (std::uint32_t r = (rows.begin + s - 1) / s * s; r < rows.end; r += s) {
        organized_normals(cloud, p.crease.normals, normals, {r, r + 1});
      }
    } else {
      organized_normals(cloud, p.crease.normals, normals, rows);
    }
  }
  const CreaseTest test{pts, nx_.data(), ny_.data(), nz_.data(),
                        std::cos(p.crease.min_angle_deg * 3.14159265F / 180.0F)};
  std::size_t m = 0, pending = 0;
  for (std::size_t r = first_row, i = first_row * w; r <= last_row && r < h; ++r) {
    for (std::size_t c = 0; c < w; ++c, ++i) {
      if (mask_[i] == 0) continue;
      if (scattered) {
        std::array<std::uint32_t, 5> at{};
        std::size_t k = 0;
        at[k++] = static_cast<std::uint32_t>(i);
        if (c >= g && c + g < w)
          at[k++] = static_cast<std::uint32_t>(i - g), at[k++] = static_cast<std::uint32_t>(i + g);
        if (r >= g && r + g < h)
          at[k++] = static_cast<std::uint32_t>(i - g * w),
          at[k++] = static_cast<std::uint32_t>(i + g * w);
        organized_normals_at(cloud, p.crease.normals, normals, std::span(at).first(k));
      }
      members_[m++] = static_cast<std::uint32_t>(i);
      // A prism pixel without a normal sits on a depth edge (or the image border): a boundary too.
      const bool crease = !std::isfinite(nx_[i]) ||
                          (c >= g && c + g < w && test.concave(i - g, i + g)) ||
                          (r >= g && r + g < h && test.concave(i - g * w, i + g * w));
      off_crease_[i] = crease ? 0 : 1;
      round_[i] = crease ? UNATTACHED : 0;
      pending_[pending] = static_cast<std::uint32_t>(i);
      pending += crease ? 1U : 0U;
    }
  }
  const auto labels = std::span(labels_).first(n);
  auto clusters = euclidean_cluster_organized(cloud, std::span(off_crease_).first(n), p.cluster,
                                              cluster_scratch_, labels);
  if (!clusters) return clusters;
  // Crease pixels take the label of the nearest labelled pixel within the window and tolerance;
  // round k only reads pixels labelled before it, so a band fills from both of its sides evenly.
  const std::size_t rad = p.cluster.pixel_radius, step = p.cluster.pixel_step;
  const float tol2 = p.cluster.tolerance * p.cluster.tolerance;
  for (std::uint32_t k = 1; k <= p.crease.attach_rounds && k < UNATTACHED; ++k) {
    std::size_t still = 0;  // the pending list, compacted as pixels attach
    for (std::size_t q = 0; q < pending; ++q) {
      const std::uint32_t i = pending_[q];
      const std::size_t r = i / w, c = i % w;
      float best = tol2;
      std::int32_t label = -1;
      // Thinned frames label grid pixels only (r, c and rad are multiples of the stride there).
      for (std::size_t rr = r >= rad ? r - rad : 0; rr <= std::min(h - 1, r + rad); rr += step) {
        for (std::size_t cc = c >= rad ? c - rad : 0; cc <= std::min(w - 1, c + rad); cc += step) {
          const std::size_t j = rr * w + cc;
          if (labels[j] < 0 || round_[j] >= k) continue;
          const float dx = pts.x[j] - pts.x[i], dy = pts.y[j] - pts.y[i], dz = pts.z[j] - pts.z[i];
          const float d2 = dx * dx + dy * dy + dz * dz;
          if (d2 <= best) best = d2, label = labels[j];
        }
      }
      if (label >= 0) {
        labels[i] = label;
        round_[i] = static_cast<std::uint8_t>(k);
      } else {
        pending_[still++] = i;
      }
    }
    if (still == pending) break;
    pending = still;
  }
  return clusters;
}

}  // namespace orthoflow::kernels
