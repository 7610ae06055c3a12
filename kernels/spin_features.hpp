#pragma once
/// @file
/// @brief The feature layer of the thesis's local representations (chapter 4): an object view's
/// keypoints (a voxel grid of leaf VS, the point nearest each voxel's centroid), their normals
/// (kernels/point_normals.hpp) and their spin images (kernels/spin_image.hpp). The bag of words
/// (Describer) and the dictionary's pool (learning/dictionary.hpp) both describe views this way.
#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

#include "core/result.hpp"
#include "kernels/point_cloud.hpp"
#include "kernels/spin_image.hpp"
#include "kernels/voxel_grid.hpp"

namespace orthoflow::kernels {

/// @brief How the features are computed (thesis defaults of its bag-of-words study).
struct SpinFeatureParams {
  SpinImageParams spin{};       ///< IW 4, SL 0.05 m
  float keypoint_leaf = 0.01F;  ///< VS, metres
  float normal_radius = 0.02F;  ///< metres
};

/// @brief Why a view has no features.
enum class SpinFeatureError : std::uint8_t {
  KEYPOINTS_FAILED,  ///< the voxel grid refused the view (a view too wide for its leaf)
  BAD_PARAMS,        ///< the normals' radius or the spin images' parameters were refused
  OUT_OF_MEMORY,     ///< the scratch could not grow to the view
  TOO_MANY_POINTS,   ///< a fixed-capacity scratch (reserve()) got a larger view: nothing computed
};
[[nodiscard]] const char* to_string(SpinFeatureError error) noexcept;

/// @brief Scratch and result of one view's features. Grows to the largest view it has seen (then
/// allocation-free), or, after reserve(), holds a fixed capacity and never allocates again (a
/// larger view is refused: TOO_MANY_POINTS). @note Not thread-safe: one per thread.
class SpinFeatures {
 public:
  SpinFeatures() = default;
  /// @brief Sizes the scratch for views of up to @p max_points points (every point may be a
  /// keypoint) and fixes it there: compute() allocates nothing from now on.
  void reserve(std::size_t max_points, std::uint32_t image_width);
  /// @brief The fixed capacity in points, or 0 while the scratch grows.
  [[nodiscard]] std::size_t fixed_capacity() const noexcept { return fixed_ ? capacity_ : 0; }
  /// @brief Computes the features of @p points. @return the keypoints (images() has one image of
  /// spin_image_bins(IW) values per keypoint; an image without weight is all zeros).
  [[nodiscard]] Result<std::size_t, SpinFeatureError> compute(PointsView points,
                                                              const SpinFeatureParams& params);
  /// @brief The last compute()'s images, keypoint after keypoint.
  [[nodiscard]] std::span<const float> images() const noexcept {
    return std::span<const float>(images_).subspan(0, used_);
  }
  /// @brief How many of them have weight.
  [[nodiscard]] std::size_t described() const noexcept { return described_; }

 private:
  VoxelGridScratch voxel_scratch_{0};
  std::vector<float> centroids_;  ///< 3 x points
  std::vector<std::uint32_t> keypoints_;
  std::vector<float> normals_;  ///< 3 x points
  std::vector<float> images_;
  std::size_t used_ = 0;
  std::size_t described_ = 0;
  std::size_t capacity_ = 0;  ///< points the arrays hold
  bool fixed_ = false;
};

}  // namespace orthoflow::kernels
