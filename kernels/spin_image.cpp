#include "kernels/spin_image.hpp"

#include <array>
#include <cmath>

#include "kernels/detail/number_text.hpp"
#include "kernels/detail/spin_image_kernel.hpp"

namespace orthoflow::kernels {

std::string SpinImageError::to_string() const {
  switch (code) {
    case Code::INVALID_WIDTH:
      return "spin_images: image width " + detail::count_text(value) + " (must be 1 to " +
             std::to_string(MAX_SPIN_IMAGE_WIDTH) + ")";
    case Code::INVALID_SUPPORT:
      return "spin_images: invalid support " + detail::value_text(value) +
             " (the length must be finite and > 0, the angle's cosine in [0, 1])";
    case Code::NORMALS_SIZE:
      return "spin_images: " + detail::count_text(value) + " normals, fewer than the points";
    case Code::BAD_KEYPOINT:
      return "spin_images: keypoint index " + detail::count_text(value) + " is past the last point";
    case Code::OUTPUT_TOO_SMALL:
      return "spin_images: output too small for " + detail::count_text(value) + " floats";
  }
  return "spin_images: unknown error";
}

namespace {

using Neighbours = std::size_t (*)(const detail::SpinSetup&, const detail::SpinKey&, PointsView,
                                   PointsView, double*);

std::size_t neighbours_scalar(const detail::SpinSetup& s, const detail::SpinKey& k,
                              PointsView points, PointsView normals, double* acc) noexcept {
  return detail::spin_range(s, k, points, normals, 0, points.size(), acc);
}

std::size_t neighbours_simd(const detail::SpinSetup& s, const detail::SpinKey& k, PointsView points,
                            PointsView normals, double* acc) noexcept {
  static auto dispatched = xsimd::dispatch<SimdArchs>(detail::SpinNeighboursKernel{});
  return dispatched(s, k, points, normals, acc);
}

Result<std::size_t, SpinImageError> run(PointsView points, PointsView normals,
                                        std::span<const std::uint32_t> keypoints,
                                        const SpinImageParams& params, std::span<float> out,
                                        Neighbours neighbours) noexcept {
  using Code = SpinImageError::Code;
  const std::uint32_t w = params.image_width;
  if (w == 0 || w > MAX_SPIN_IMAGE_WIDTH) return err(SpinImageError{Code::INVALID_WIDTH, 1.0 * w});
  if (!std::isfinite(params.support_length) || params.support_length <= 0.0F)
    return err(SpinImageError{Code::INVALID_SUPPORT, params.support_length});
  if (!(params.support_angle_cos >= 0.0F && params.support_angle_cos <= 1.0F))
    return err(SpinImageError{Code::INVALID_SUPPORT, params.support_angle_cos});
  if (normals.size() < points.size())
    return err(SpinImageError{Code::NORMALS_SIZE, static_cast<double>(normals.size())});
  for (const std::uint32_t k : keypoints) {
    if (k >= points.size()) return err(SpinImageError{Code::BAD_KEYPOINT, static_cast<double>(k)});
  }
  const std::size_t bins = spin_image_bins(w);
  if (out.size() < keypoints.size() * bins)
    return err(
        SpinImageError{Code::OUTPUT_TOO_SMALL, static_cast<double>(keypoints.size() * bins)});

  const detail::SpinSetup s = detail::make_spin_setup(params);
  std::array<double, spin_image_bins(MAX_SPIN_IMAGE_WIDTH)> acc{};
  std::size_t described = 0;
  for (std::size_t j = 0; j < keypoints.size(); ++j) {
    const std::uint32_t i = keypoints[j];
    const detail::SpinKey key{points.x[i],  points.y[i],  points.z[i],
                              normals.x[i], normals.y[i], normals.z[i]};
    std::fill(acc.begin(), acc.begin() + static_cast<std::ptrdiff_t>(bins), 0.0);
    const bool finite = std::isfinite(key.x) && std::isfinite(key.y) && std::isfinite(key.z) &&
                        std::isfinite(key.nx) && std::isfinite(key.ny) && std::isfinite(key.nz);
    const std::size_t found = finite ? neighbours(s, key, points, normals, acc.data()) : 0;
    double sum = 0.0;
    for (std::size_t b = 0; b < bins; ++b) sum += acc[b];
    float* image = out.data() + j * bins;
    const bool weighed = found > 1 && sum > 0.0;
    for (std::size_t b = 0; b < bins; ++b)
      image[b] = weighed ? static_cast<float>(acc[b] / sum) : 0.0F;
    described += weighed ? 1U : 0U;
  }
  return described;
}

}  // namespace

Result<std::size_t, SpinImageError> spin_images(PointsView points, PointsView normals,
                                                std::span<const std::uint32_t> keypoints,
                                                const SpinImageParams& params,
                                                std::span<float> out) noexcept {
  return run(points, normals, keypoints, params, out, neighbours_simd);
}

Result<std::size_t, SpinImageError> spin_images_scalar(PointsView points, PointsView normals,
                                                       std::span<const std::uint32_t> keypoints,
                                                       const SpinImageParams& params,
                                                       std::span<float> out) noexcept {
  return run(points, normals, keypoints, params, out, neighbours_scalar);
}

Result<std::size_t, VoxelGridError> voxel_keypoints(PointsView points, float leaf,
                                                    VoxelGridScratch& scratch, PointsSpan centroids,
                                                    std::span<std::uint32_t> out) noexcept {
  auto voxels = voxel_grid(points, leaf, scratch, centroids);
  if (!voxels) return err(voxels.error());
  std::size_t written = 0;
  for (std::size_t v = 0; v < voxels.value(); ++v) {
    const float cx = centroids.x[v], cy = centroids.y[v], cz = centroids.z[v];
    std::size_t best = points.size();
    float best_d2 = 0.0F;
    for (std::size_t p = 0; p < points.size(); ++p) {
      const float dx = points.x[p] - cx, dy = points.y[p] - cy, dz = points.z[p] - cz;
      const float d2 = dx * dx + dy * dy + dz * dz;
      if (d2 == d2 && (best == points.size() || d2 < best_d2)) {  // NaN points are never nearest
        best = p;
        best_d2 = d2;
      }
    }
    if (best == points.size()) continue;
    const auto index = static_cast<std::uint32_t>(best);
    bool again = false;
    for (std::size_t k = 0; k < written && !again; ++k) again = out[k] == index;
    if (again) continue;
    if (written == out.size())
      return err(VoxelGridError{VoxelGridError::Code::OUTPUT_TOO_SMALL,
                                static_cast<double>(voxels.value())});
    out[written++] = index;
  }
  return written;
}

}  // namespace orthoflow::kernels
