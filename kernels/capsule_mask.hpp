#pragma once
/// @file
/// @brief Points inside capsules (a segment swept by a sphere) as a per-point keep mask: what the
/// robot-body filter removes from a frame before segmentation (the arm's links as capsules,
/// manipulation/arm_body.hpp).
#include <array>
#include <cstddef>
#include <cstdint>
#include <span>

#include "kernels/point_cloud.hpp"

namespace orthoflow::kernels {

/// @brief A segment [a, b] swept by a sphere of @p radius; a == b is a sphere.
struct Capsule {
  std::array<float, 3> a{};
  std::array<float, 3> b{};
  float radius = 0.0F;
};

/// @brief At most this many capsules per call (an arm's links and hand, with room to spare).
inline constexpr std::size_t MAX_CAPSULES = 32;

/// @brief mask[i] = 0 when point i is finite and within some capsule (distance to its segment <=
/// radius, inclusive), else 1: NaN and infinite points are kept as they are (mask_organized leaves
/// them NaN). Capsules past MAX_CAPSULES, with a negative or non-finite radius or non-finite ends,
/// remove nothing.
/// @pre mask.size() >= in.size(). @return the number of points inside (removed).
/// @note Stateless, thread-safe, no allocation. The SIMD variants and the scalar twin compute the
/// same operations in the same order without fused multiply-adds: their masks are equal bit for
/// bit, on x86 and ARM.
std::size_t capsule_mask(PointsView in, std::span<const Capsule> capsules,
                         std::span<std::uint8_t> mask) noexcept;
/// @brief Scalar reference twin of capsule_mask().
std::size_t capsule_mask_scalar(PointsView in, std::span<const Capsule> capsules,
                                std::span<std::uint8_t> mask) noexcept;

}  // namespace orthoflow::kernels
