#pragma once
/// @file
/// @brief The distance between two sets of descriptors (thesis chapter 5, the objects of its
/// instance-based approaches I and II are sets of spin images):
///   D(U, V) = (1 / |U|) sum over u in U of min over v in V of ||u - v||   (Euclidean)
/// It is not symmetric: D(U, V) asks how well V explains every descriptor of U.
#include <cstddef>
#include <span>

#include "kernels/distance.hpp"

namespace orthoflow::kernels {

/// @brief D(U, V): @p u holds |U| descriptors of v.dims values each, one after another (row-major,
/// as spin_images() writes them); @p v is the stored set as a structure-of-arrays matrix.
/// @p scratch receives one row of distances (size >= v.count). Columns count..stride (spare, e.g.
/// zero padding to the SIMD width) are computed too when @p scratch and v.data hold them (size >=
/// v.stride, and >= v.dims x v.stride), and never compared: a set padded to a multiple of the lane
/// count keeps the kernel out of its scalar tail.
/// @return D(U, V); 0 when U is empty; +infinity when V is empty and U is not; NaN when a value of
/// either set is NaN (never a silently smaller distance).
/// @pre u.size() is a multiple of v.dims (v.dims > 0). @note No allocation; thread-safe;
/// deterministic. Against set_distance_scalar(): within 1e-5 relative (distances()' tolerance for
/// L2).
[[nodiscard]] float set_distance(std::span<const float> u, DescriptorMatrixView v,
                                 std::span<float> scratch) noexcept;
/// @brief Scalar reference twin of set_distance() (distances_scalar()).
[[nodiscard]] float set_distance_scalar(std::span<const float> u, DescriptorMatrixView v,
                                        std::span<float> scratch) noexcept;

}  // namespace orthoflow::kernels
