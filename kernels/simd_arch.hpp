#pragma once
/// @file
/// @brief The instruction sets a kernel is compiled for, and which one run-time dispatch picks.
///
/// How a SIMD kernel is built (STYLE rule 3):
/// - `kernels/detail/<name>.inl` defines `template <class Arch> R <Name>Kernel::operator()(Arch,
/// ...) const`
///   and ends with `#ifdef OF_SIMD_ARCH` + an explicit instantiation for `OF_SIMD_ARCH`.
/// - CMake (`orthoflow_simd_sources`) generates one translation unit per architecture that defines
///   `OF_SIMD_ARCH` and includes the .inl, compiled with that architecture's flags only.
/// - `kernels/<name>.cpp` declares the functor (body not visible) and calls it through
///   `xsimd::dispatch<SimdArchs>`; the `_scalar` twin lives beside it.
#include <xsimd/xsimd.hpp>

namespace orthoflow::kernels {

#if defined(__x86_64__) || defined(_M_X64)
/// @brief Best first: AVX-512BW, AVX2+FMA, SSE2 (the x86-64 baseline, always available).
using SimdArchs = xsimd::arch_list<xsimd::avx512bw, xsimd::fma3<xsimd::avx2>, xsimd::sse2>;
#elif defined(__aarch64__)
/// @brief NEON is part of the AArch64 baseline.
using SimdArchs = xsimd::arch_list<xsimd::neon64>;
#else
#error "orthoflow kernels support x86-64 and aarch64"
#endif

/// @brief Name of the architecture xsimd::dispatch<SimdArchs> selects on this CPU ("avx512bw",
/// "fma3+avx2", "sse2" or "arm64+neon"). @note Thread-safe; constant for the process lifetime.
const char* simd_arch_name() noexcept;

/// @brief Calls @p f(Arch{}) for every architecture in SimdArchs that this CPU supports, best
/// first. For tests and benchmarks that compare each compiled variant with the scalar twin.
template <class F>
void for_each_available_arch(F&& f) {
  auto visit = [&f]<class... Archs>(xsimd::arch_list<Archs...>) {
    const unsigned best = xsimd::available_architectures().best;
    ((Archs::version() <= best ? f(Archs{}) : void()), ...);
  };
  visit(SimdArchs{});
}

}  // namespace orthoflow::kernels
