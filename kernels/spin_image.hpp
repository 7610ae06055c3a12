#pragma once
/// @file
/// @brief Spin images (Johnson and Hebert; thesis chapter 4) at keypoints of an object view, with
/// PCL's `SpinImageEstimation` semantics (rectangular, not angular, the keypoint's normal as the
/// axis), and the keypoints themselves (a voxel grid, then the point nearest each voxel's
/// centroid).
///
/// For a keypoint k with normal n, every point p of the view with |p - k|^2 < R^2 (float, R the
/// support length; k itself counts) is a neighbour. With d = p - k:
///   beta = |d| cos,  alpha = |d| sqrt(1 - cos^2),  cos = clamp((d . n) / |d|, -1, 1)
/// (d, |d| and d . n in float, the rest in double, as PCL). A neighbour with |beta| or alpha at or
/// beyond W * s, s = R / W / sqrt(2), is outside the cylinder and skipped, and so is k itself
/// (|d| < 10 DBL_EPSILON). Each remaining one adds bilinear weights to the four nodes around
/// (alpha / s, beta / s + W) of a (W + 1) x (2W + 1) image (row = alpha, column = beta; row-major
/// output). With support_angle_cos > 0, a neighbour whose normal makes |n_k . n_p| below it is
/// skipped too. The image is divided by its sum (it sums to 1).
///
/// Unlike PCL: an image with no weight (at most one neighbour, every neighbour skipped, or a
/// keypoint or normal that is not finite) is all zeros and is not counted as described (PCL writes
/// zeros, or NaN when every neighbour was skipped); a normal that is not unit length is used as it
/// is, its cosines clamped (PCL throws).
#include <cstddef>
#include <cstdint>
#include <span>
#include <string>

#include "core/result.hpp"
#include "kernels/point_cloud.hpp"
#include "kernels/voxel_grid.hpp"

namespace orthoflow::kernels {

/// @brief Spin-image parameters (thesis chapter 4; defaults: its bag-of-words study, IW 4, SL 5
/// cm).
struct SpinImageParams {
  std::uint32_t image_width = 4;   ///< W: W + 1 alpha rows, 2W + 1 beta columns
  float support_length = 0.05F;    ///< R, metres: the neighbourhood's radius
  float support_angle_cos = 0.0F;  ///< 0 = every neighbour; else the least |n_k . n_p| kept
};

/// @brief The largest image width spin_images() takes (17 x 33 = 561 bins).
inline constexpr std::uint32_t MAX_SPIN_IMAGE_WIDTH = 16;

/// @brief The bins of one image of width @p w: (w + 1)(2w + 1).
[[nodiscard]] constexpr std::size_t spin_image_bins(std::uint32_t w) noexcept {
  return (static_cast<std::size_t>(w) + 1) * (2 * static_cast<std::size_t>(w) + 1);
}

/// @brief Why spin_images() refused to run; to_string() says what and with which value.
struct SpinImageError {
  enum class Code : std::uint8_t {
    INVALID_WIDTH,     ///< image_width 0 or above MAX_SPIN_IMAGE_WIDTH
    INVALID_SUPPORT,   ///< support_length not finite or <= 0, support_angle_cos outside [0, 1]
    NORMALS_SIZE,      ///< fewer normals than points
    BAD_KEYPOINT,      ///< a keypoint index at or past the point count
    OUTPUT_TOO_SMALL,  ///< fewer than keypoints x bins floats
  };
  Code code = Code::INVALID_WIDTH;
  double value = 0.0;  ///< the offending parameter, size or index
  [[nodiscard]] std::string to_string() const;
};

/// @brief The spin image of every keypoint of @p points (indices @p keypoints, normals @p normals,
/// one per point), written to @p out: image j at out[j * bins, (j + 1) * bins).
/// @return the number of images with weight (the others are zeros), or an error (nothing written).
/// @note Stateless, thread-safe, allocation-free. The SIMD variants find the neighbours with the
/// scalar twin's float operations in its order (no fused multiply-adds) and share its double
/// binning: their images are equal bit for bit, on x86 and ARM.
[[nodiscard]] Result<std::size_t, SpinImageError> spin_images(
    PointsView points, PointsView normals, std::span<const std::uint32_t> keypoints,
    const SpinImageParams& params, std::span<float> out) noexcept;
/// @brief Scalar reference twin of spin_images().
[[nodiscard]] Result<std::size_t, SpinImageError> spin_images_scalar(
    PointsView points, PointsView normals, std::span<const std::uint32_t> keypoints,
    const SpinImageParams& params, std::span<float> out) noexcept;

/// @brief Keypoints of an object view (thesis chapter 4): the voxel grid of side @p leaf (PCL's
/// voxel rule, kernels/voxel_grid.hpp), and for each occupied voxel's centroid the index of the
/// nearest point of @p points (ties: the lowest index), in voxel order; two voxels may give the
/// same point, which is then written once.
/// @p centroids holds the voxel grid's output (at least as many points as @p points).
/// @return the number of indices written to @p out, or the voxel grid's error.
/// @note Allocation-free with its scratch; deterministic.
[[nodiscard]] Result<std::size_t, VoxelGridError> voxel_keypoints(
    PointsView points, float leaf, VoxelGridScratch& scratch, PointsSpan centroids,
    std::span<std::uint32_t> out) noexcept;

}  // namespace orthoflow::kernels
