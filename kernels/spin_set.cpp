#include "kernels/spin_set.hpp"

#include <algorithm>
#include <cmath>

namespace orthoflow::kernels {

bool SpinSetParams::valid() const noexcept {
  const auto positive = [](float v) { return std::isfinite(v) && v > 0.0F; };
  const SpinImageParams& s = features.spin;
  return s.image_width >= 1 && s.image_width <= MAX_SPIN_IMAGE_WIDTH &&
         positive(s.support_length) && s.support_angle_cos >= 0.0F && s.support_angle_cos <= 1.0F &&
         positive(features.keypoint_leaf) && positive(features.normal_radius) &&
         max_keypoints >= 1 && max_keypoints <= MAX_SET_KEYPOINTS;
}

std::size_t write_spin_set(std::span<const float> images, std::size_t image_values,
                           std::uint32_t max_keypoints, std::span<float> out) noexcept {
  std::fill(out.begin(), out.end(), 0.0F);
  const std::size_t rows = images.size() / image_values;
  const auto weighted = [&](std::size_t r) {
    const std::span<const float> image = images.subspan(r * image_values, image_values);
    return std::any_of(image.begin(), image.end(), [](float v) { return v != 0.0F; });
  };
  std::size_t described = 0;
  for (std::size_t r = 0; r < rows; ++r) described += weighted(r) ? 1 : 0;
  const std::size_t kept = std::min<std::size_t>(described, max_keypoints);
  // The i-th image kept is the floor(i described / kept)-th image with weight.
  std::size_t next = 0, seen = 0, written = 0;
  for (std::size_t r = 0; r < rows && written < kept; ++r) {
    if (!weighted(r)) continue;
    if (seen == next) {
      std::copy_n(images.begin() + static_cast<std::ptrdiff_t>(r * image_values), image_values,
                  out.begin() + static_cast<std::ptrdiff_t>(1 + written * image_values));
      ++written;
      next = written * described / kept;
    }
    ++seen;
  }
  out[0] = static_cast<float>(written);
  return written;
}

std::optional<std::size_t> spin_set_count(std::span<const float> descriptor,
                                          std::size_t image_values) noexcept {
  if (image_values == 0 || descriptor.empty() || (descriptor.size() - 1) % image_values != 0)
    return std::nullopt;
  const std::size_t capacity = (descriptor.size() - 1) / image_values;
  const float n = descriptor[0];
  if (!(n >= 1.0F) || n > static_cast<float>(capacity) || n != std::floor(n)) return std::nullopt;
  const std::size_t count = static_cast<std::size_t>(n);
  const std::span<const float> used = descriptor.subspan(1, count * image_values);
  const std::span<const float> rest = descriptor.subspan(1 + count * image_values);
  if (!std::all_of(used.begin(), used.end(), [](float v) { return std::isfinite(v); }) ||
      !std::all_of(rest.begin(), rest.end(), [](float v) { return v == 0.0F; }))
    return std::nullopt;
  return count;
}

}  // namespace orthoflow::kernels
