#pragma once
// The distances() SIMD functor (body in distance.inl, one TU per arch) and the per-element terms
// shared by the scalar twin and the SIMD tail.
#include <cmath>
#include <cstddef>
#include <span>

#include "kernels/distance.hpp"
#include "kernels/simd_arch.hpp"

namespace orthoflow::kernels::detail {

struct DistanceKernel {
  template <class Arch>
  void operator()(Arch arch, std::span<const float> query, DescriptorMatrixView stored,
                  Metric metric, std::span<float> out) const noexcept;
};

inline float xlogx(float v) noexcept { return v > 0.0F ? v * std::log(v) : 0.0F; }

/// One dimension's contribution for metric M (a = query value, b = stored value).
template <Metric M>
inline float distance_term(float a, float b) noexcept {
  if constexpr (M == Metric::L1) {
    return std::abs(a - b);
  } else if constexpr (M == Metric::L2 || M == Metric::L2_SQUARED) {
    const float d = a - b;
    return d * d;
  } else if constexpr (M == Metric::CHI_SQUARED) {
    const float d = a - b;
    const float s = a + b;
    return s > 0.0F ? d * d / s : 0.0F;
  } else if constexpr (M == Metric::SYMMETRIC_KL) {
    return (a - b) * (std::log(a + DISTANCE_KL_EPSILON) - std::log(b + DISTANCE_KL_EPSILON));
  } else {
    // a ln(2a/m) + b ln(2b/m) = xlogx(a) + xlogx(b) - xlogx(m) + m ln 2, m = a + b
    const float m = a + b;
    return xlogx(a) + xlogx(b) - xlogx(m) + m * 0.693147180559945F;
  }
}

/// Final step after summing the terms.
template <Metric M>
inline float distance_finish(float sum) noexcept {
  if constexpr (M == Metric::L2) { return std::sqrt(sum); }
  if constexpr (M == Metric::JENSEN_SHANNON) { return 0.5F * sum; }
  return sum;
}

/// Scalar distances for columns [begin, end).
template <Metric M>
inline void distance_columns_scalar(std::span<const float> query, DescriptorMatrixView s,
                                    std::size_t begin, std::size_t end,
                                    std::span<float> out) noexcept {
  for (std::size_t j = begin; j < end; ++j) {
    float acc = 0.0F;
    for (std::size_t d = 0; d < s.dims; ++d) {
      acc += distance_term<M>(query[d], s.data[d * s.stride + j]);
    }
    out[j] = distance_finish<M>(acc);
  }
}

inline void distance_columns_scalar(std::span<const float> query, DescriptorMatrixView s,
                                    Metric metric, std::size_t begin, std::size_t end,
                                    std::span<float> out) noexcept {
  switch (metric) {
    case Metric::L1:
      return distance_columns_scalar<Metric::L1>(query, s, begin, end, out);
    case Metric::L2:
      return distance_columns_scalar<Metric::L2>(query, s, begin, end, out);
    case Metric::L2_SQUARED:
      return distance_columns_scalar<Metric::L2_SQUARED>(query, s, begin, end, out);
    case Metric::CHI_SQUARED:
      return distance_columns_scalar<Metric::CHI_SQUARED>(query, s, begin, end, out);
    case Metric::SYMMETRIC_KL:
      return distance_columns_scalar<Metric::SYMMETRIC_KL>(query, s, begin, end, out);
    case Metric::JENSEN_SHANNON:
      return distance_columns_scalar<Metric::JENSEN_SHANNON>(query, s, begin, end, out);
  }
}

}  // namespace orthoflow::kernels::detail
