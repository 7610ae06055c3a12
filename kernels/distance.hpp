#pragma once
/// @file
/// @brief Distances between one query descriptor and N stored descriptors, and the k nearest of
/// them. Stored descriptors form a structure-of-arrays matrix: value d of descriptor j is data[d *
/// stride + j], so one SIMD register holds dimension d of several descriptors and a query is
/// compared with many at once. Metrics for histograms (non-negative values, e.g. GOOD blocks):
/// - L1 = sum |a - b|;  L2_SQUARED = sum (a - b)^2;  L2 = sqrt(L2_SQUARED)
/// - CHI_SQUARED = sum (a - b)^2 / (a + b), terms with a + b == 0 count 0 (no factor 1/2)
/// - SYMMETRIC_KL = KL(a||b) + KL(b||a) = sum (a - b) (ln(a + e) - ln(b + e)), e =
/// DISTANCE_KL_EPSILON
/// - JENSEN_SHANNON = 1/2 sum [a ln(2a / (a + b)) + b ln(2b / (a + b))], 0 ln 0 = 0 (nats, in [0,
/// ln 2] per
///   unit-sum histogram pair)
#include <cstddef>
#include <cstdint>
#include <span>

namespace orthoflow::kernels {

/// @brief The distance measures distances() computes.
enum class Metric : std::uint8_t { L1, L2, L2_SQUARED, CHI_SQUARED, SYMMETRIC_KL, JENSEN_SHANNON };
/// @brief "l1", "l2", "l2_squared", "chi_squared", "symmetric_kl" or "jensen_shannon".
[[nodiscard]] const char* to_string(Metric metric) noexcept;

/// @brief Smoothing added to both histograms by SYMMETRIC_KL so that empty bins stay finite.
inline constexpr float DISTANCE_KL_EPSILON = 1e-6F;

/// @brief Read-only structure-of-arrays matrix of @p count descriptors of @p dims values each.
struct DescriptorMatrixView {
  std::span<const float> data;  ///< data[d * stride + j] = value d of descriptor j
  std::size_t dims = 0;
  std::size_t count = 0;
  std::size_t stride =
      0;  ///< >= count; lets a store keep spare columns for descriptors still to come
};

/// @brief One neighbour: the stored descriptor's column and its distance to the query.
struct Neighbor {
  std::size_t index = 0;
  float distance = 0.0F;
};

/// @brief Writes the distance from @p query to each stored descriptor into out[0..count).
/// @pre query.size() == stored.dims, stored.stride >= stored.count,
/// stored.data.size() >= (dims - 1) * stride + count (or count == 0), out.size() >= stored.count.
/// Violations are bugs (OF_ENFORCE). @return stored.count.
/// @note No allocation; thread-safe; deterministic. Tolerance against distances_scalar(): L1 exact;
/// L2, L2_SQUARED and CHI_SQUARED within 1e-5 relative (the AVX units may fuse a*b+c into FMA);
/// SYMMETRIC_KL and JENSEN_SHANNON within 1e-4 relative + 1e-6 absolute (vector log vs std::log).
std::size_t distances(std::span<const float> query, DescriptorMatrixView stored, Metric metric,
                      std::span<float> out) noexcept;
/// @brief Scalar reference twin of distances().
std::size_t distances_scalar(std::span<const float> query, DescriptorMatrixView stored,
                             Metric metric, std::span<float> out) noexcept;

/// @brief The min(k, count) stored descriptors nearest to @p query, nearest first, k = out.size();
/// equal distances keep the lower index first; NaN distances rank last.
/// @pre as distances(), and scratch.size() >= stored.count (it receives every distance).
/// @return the number of neighbours written. @note No allocation; thread-safe; deterministic.
std::size_t nearest_k(std::span<const float> query, DescriptorMatrixView stored, Metric metric,
                      std::span<float> scratch, std::span<Neighbor> out) noexcept;
/// @brief nearest_k() computed with distances_scalar().
std::size_t nearest_k_scalar(std::span<const float> query, DescriptorMatrixView stored,
                             Metric metric, std::span<float> scratch,
                             std::span<Neighbor> out) noexcept;

}  // namespace orthoflow::kernels
