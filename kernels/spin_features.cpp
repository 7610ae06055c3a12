#include "kernels/spin_features.hpp"

#include <new>

#include "kernels/point_normals.hpp"

namespace orthoflow::kernels {

const char* to_string(SpinFeatureError error) noexcept {
  switch (error) {
    case SpinFeatureError::KEYPOINTS_FAILED:
      return "spin features: the keypoints' voxel grid refused the view (too wide for its leaf)";
    case SpinFeatureError::BAD_PARAMS:
      return "spin features: the normals' radius or the spin images' parameters were refused";
    case SpinFeatureError::OUT_OF_MEMORY:
      return "spin features: out of memory for the view's scratch";
    case SpinFeatureError::TOO_MANY_POINTS:
      return "spin features: the view has more points than the scratch was reserved for";
  }
  return "spin features: unknown error";
}

void SpinFeatures::reserve(std::size_t max_points, std::uint32_t image_width) {
  voxel_scratch_ = VoxelGridScratch(max_points);
  centroids_.assign(3 * max_points, 0.0F);
  keypoints_.assign(max_points, 0);
  normals_.assign(3 * max_points, 0.0F);
  images_.assign(max_points * spin_image_bins(image_width), 0.0F);
  capacity_ = max_points;
  fixed_ = true;
}

Result<std::size_t, SpinFeatureError> SpinFeatures::compute(PointsView points,
                                                            const SpinFeatureParams& params) {
  used_ = described_ = 0;
  const std::size_t n = points.size();
  const std::size_t bins = spin_image_bins(params.spin.image_width);
  if (fixed_ && (n > capacity_ || n * bins > images_.size()))
    return err(SpinFeatureError::TOO_MANY_POINTS);
  try {
    if (capacity_ < n) {
      voxel_scratch_ = VoxelGridScratch(n);
      centroids_.resize(3 * n);
      keypoints_.resize(n);
      normals_.resize(3 * n);
      capacity_ = n;
    }
  } catch (const std::bad_alloc&) { return err(SpinFeatureError::OUT_OF_MEMORY); }
  const std::span<float> c(centroids_.data(), 3 * n);
  const PointsSpan centroids{c.subspan(0, n), c.subspan(n, n), c.subspan(2 * n, n)};
  auto k = voxel_keypoints(points, params.keypoint_leaf, voxel_scratch_, centroids,
                           std::span<std::uint32_t>(keypoints_.data(), n));
  if (!k) return err(SpinFeatureError::KEYPOINTS_FAILED);
  const std::span<const std::uint32_t> keys(keypoints_.data(), k.value());
  const std::span<float> nv(normals_.data(), 3 * n);
  const PointsSpan normals{nv.subspan(0, n), nv.subspan(n, n), nv.subspan(2 * n, n)};
  PointNormalParams np;
  np.radius = params.normal_radius;
  if (!point_normals(points, keys, np, normals)) return err(SpinFeatureError::BAD_PARAMS);
  try {
    if (images_.size() < keys.size() * bins) images_.resize(keys.size() * bins);
  } catch (const std::bad_alloc&) { return err(SpinFeatureError::OUT_OF_MEMORY); }
  used_ = keys.size() * bins;
  auto described =
      spin_images(points, normals, keys, params.spin, std::span<float>(images_.data(), used_));
  if (!described) {
    used_ = 0;
    return err(SpinFeatureError::BAD_PARAMS);
  }
  described_ = described.value();
  return keys.size();
}

}  // namespace orthoflow::kernels
