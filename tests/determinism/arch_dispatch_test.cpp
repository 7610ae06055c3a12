// The run-time dispatch picks the best architecture the build targets: NEON on aarch64, an x86 one
// (AVX-512BW, AVX2+FMA or SSE2, depending on the CPU) on x86-64. Guards the aarch64 preset against
// a build that silently falls back to an unexpected architecture list.
#include <gtest/gtest.h>

#include <set>
#include <string>

#include <xsimd/xsimd.hpp>

#include "kernels/simd_arch.hpp"

namespace {

namespace ok = orthoflow::kernels;

TEST(ArchDispatch, BestArchitectureMatchesTheTarget) {
  const std::string name = ok::simd_arch_name();
  std::printf("dispatched: %s\n", name.c_str());
#if defined(__aarch64__)
  EXPECT_EQ(name, "arm64+neon");
  EXPECT_EQ(name, xsimd::neon64::name());
#elif defined(__x86_64__)
  const std::set<std::string> x86{"avx512bw", "fma3+avx2", "sse2"};
  EXPECT_TRUE(x86.count(name) == 1) << name;
#else
  FAIL() << "unsupported target";
#endif
}

TEST(ArchDispatch, DispatchedArchitectureIsTheBestAvailableOne) {
  std::string first;
  int count = 0;
  ok::for_each_available_arch([&](auto arch) {
    if (count++ == 0) { first = decltype(arch)::name(); }
  });
  ASSERT_GE(count, 1);
  EXPECT_EQ(first, ok::simd_arch_name());
#if defined(__aarch64__)
  EXPECT_EQ(count, 1);  // NEON is the only aarch64 variant, and it is always present
#endif
}

}  // namespace
