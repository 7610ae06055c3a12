#pragma once
/// @file
/// @brief A view as the set of its spin images (thesis chapter 5: the objects of the instance-based
/// approaches I and II are sets of spin images, compared by D(U, V), kernels/set_distance.hpp).
/// A set travels as one fixed-length descriptor, so that the learners' batches, the evaluation's
/// cache and the graph's blocks carry it like any other:
///   [n, image_1, ..., image_n, 0 ... 0]   length 1 + max_keypoints x spin_image_bins(IW)
/// n is the number of images (a whole number, 1..max_keypoints), each image spin_image_bins(IW)
/// values, and the rest is zero.
#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>

#include "kernels/spin_features.hpp"

namespace orthoflow::kernels {

/// @brief Most images one set may hold.
inline constexpr std::uint32_t MAX_SET_KEYPOINTS = 4096;

/// @brief The parameters of a spin-image set.
struct SpinSetParams {
  /// The thesis's defaults for sets (its parameter study of approach II, chapter 5): IW 8, SL 0.10
  /// m, VS 0.04 m (approach I's best was VS 0.05 m); normals of radius 0.02 m. The bag of words
  /// keeps IW 4, SL 0.05 m, VS 0.01 m (SpinFeatureParams' defaults).
  SpinFeatureParams features{SpinImageParams{8, 0.10F, 0.0F}, 0.04F, 0.02F};
  /// A view with more described keypoints keeps this many, evenly spaced in keypoint order.
  std::uint32_t max_keypoints = 128;
  [[nodiscard]] bool operator==(const SpinSetParams& o) const noexcept {
    return features.spin.image_width == o.features.spin.image_width &&
           features.spin.support_length == o.features.spin.support_length &&
           features.spin.support_angle_cos == o.features.spin.support_angle_cos &&
           features.keypoint_leaf == o.features.keypoint_leaf &&
           features.normal_radius == o.features.normal_radius && max_keypoints == o.max_keypoints;
  }
  /// @brief Image width 1..MAX_SPIN_IMAGE_WIDTH, finite positive support length, leaf and normal
  /// radius, the support angle's cosine in [0, 1], 1..MAX_SET_KEYPOINTS keypoints.
  [[nodiscard]] bool valid() const noexcept;
  /// @brief Values of one image: spin_image_bins(image width).
  [[nodiscard]] std::size_t image_values() const noexcept {
    return spin_image_bins(features.spin.image_width);
  }
  /// @brief Values of one set descriptor: 1 + max_keypoints x image_values().
  [[nodiscard]] std::size_t length() const noexcept {
    return 1 + static_cast<std::size_t>(max_keypoints) * image_values();
  }
};

/// @brief Writes the set of @p images (keypoint after keypoint, @p image_values each, as
/// SpinFeatures::images() holds them) to @p out, which it fills entirely: the images with weight
/// (an all-zero image has no neighbour), at most @p max_keypoints of them, evenly spaced in order
/// (image floor(i n / max_keypoints) for i < max_keypoints) when there are more.
/// @return the images written (0: none had weight). @pre out.size() == 1 + max_keypoints x
/// image_values, image_values > 0. @note No allocation; deterministic.
std::size_t write_spin_set(std::span<const float> images, std::size_t image_values,
                           std::uint32_t max_keypoints, std::span<float> out) noexcept;

/// @brief The images of a set descriptor (its first value), or std::nullopt when it is not one:
/// a length other than 1 + k x @p image_values, a count that is not a whole number in 1..k, a
/// value that is not finite, or a value past the last image that is not zero.
[[nodiscard]] std::optional<std::size_t> spin_set_count(std::span<const float> descriptor,
                                                        std::size_t image_values) noexcept;

}  // namespace orthoflow::kernels
