#pragma once
// SIMD body of distances(): lanes hold different stored descriptors (structure of arrays), so every
// lane sums its own terms over d in the same order as the scalar twin. Four registers of columns
// are processed together to hide the add latency, then one register, then the scalar tail.
#include "kernels/detail/distance_kernel.hpp"

namespace orthoflow::kernels::detail {

namespace distance_simd {

template <class B>
B xlogx(const B& v) noexcept {
  return xsimd::select(v > B(0.0F), v * xsimd::log(v), B(0.0F));
}

template <Metric M, class B>
B term(const B& a, const B& b) noexcept {
  if constexpr (M == Metric::L1) {
    return xsimd::abs(a - b);
  } else if constexpr (M == Metric::L2 || M == Metric::L2_SQUARED) {
    const B d = a - b;
    return d * d;
  } else if constexpr (M == Metric::CHI_SQUARED) {
    const B d = a - b;
    const B s = a + b;
    return xsimd::select(s > B(0.0F), d * d / s, B(0.0F));
  } else if constexpr (M == Metric::SYMMETRIC_KL) {
    const B e(DISTANCE_KL_EPSILON);
    return (a - b) * (xsimd::log(a + e) - xsimd::log(b + e));
  } else {
    const B m = a + b;
    return xlogx(a) + xlogx(b) - xlogx(m) + m * B(0.693147180559945F);
  }
}

template <Metric M, class B>
B finish(const B& sum) noexcept {
  if constexpr (M == Metric::L2) { return xsimd::sqrt(sum); }
  if constexpr (M == Metric::JENSEN_SHANNON) { return B(0.5F) * sum; }
  return sum;
}

template <Metric M, class Arch>
void run(std::span<const float> query, DescriptorMatrixView s, std::span<float> out) noexcept {
  using B = xsimd::batch<float, Arch>;
  constexpr std::size_t L = B::size;
  std::size_t j = 0;
  for (; j + 4 * L <= s.count; j += 4 * L) {
    B acc[4] = {B(0.0F), B(0.0F), B(0.0F), B(0.0F)};
    for (std::size_t d = 0; d < s.dims; ++d) {
      const B q(query[d]);
      const float* row = s.data.data() + d * s.stride + j;
      for (std::size_t u = 0; u < 4; ++u) {
        acc[u] = acc[u] + term<M>(q, B::load_unaligned(row + u * L));
      }
    }
    for (std::size_t u = 0; u < 4; ++u) {
      finish<M>(acc[u]).store_unaligned(out.data() + j + u * L);
    }
  }
  for (; j + L <= s.count; j += L) {
    B acc(0.0F);
    for (std::size_t d = 0; d < s.dims; ++d) {
      acc = acc + term<M>(B(query[d]), B::load_unaligned(s.data.data() + d * s.stride + j));
    }
    finish<M>(acc).store_unaligned(out.data() + j);
  }
  distance_columns_scalar<M>(query, s, j, s.count, out);
}

}  // namespace distance_simd

template <class Arch>
void DistanceKernel::operator()(Arch /*arch*/, std::span<const float> query,
                                DescriptorMatrixView stored, Metric metric,
                                std::span<float> out) const noexcept {
  switch (metric) {
    case Metric::L1:
      return distance_simd::run<Metric::L1, Arch>(query, stored, out);
    case Metric::L2:
      return distance_simd::run<Metric::L2, Arch>(query, stored, out);
    case Metric::L2_SQUARED:
      return distance_simd::run<Metric::L2_SQUARED, Arch>(query, stored, out);
    case Metric::CHI_SQUARED:
      return distance_simd::run<Metric::CHI_SQUARED, Arch>(query, stored, out);
    case Metric::SYMMETRIC_KL:
      return distance_simd::run<Metric::SYMMETRIC_KL, Arch>(query, stored, out);
    case Metric::JENSEN_SHANNON:
      return distance_simd::run<Metric::JENSEN_SHANNON, Arch>(query, stored, out);
  }
}

}  // namespace orthoflow::kernels::detail

#ifdef OF_SIMD_ARCH
template void orthoflow::kernels::detail::DistanceKernel::operator()<OF_SIMD_ARCH>(
    OF_SIMD_ARCH, std::span<const float>, orthoflow::kernels::DescriptorMatrixView,
    orthoflow::kernels::Metric, std::span<float>) const noexcept;
#endif
