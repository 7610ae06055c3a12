// Kinect v1 packed-stream unpacking on one 640x480 frame: the dispatched SIMD kernel against the
// scalar twin, for the 11-bit depth and the 10-bit depth/IR streams, and each compiled
// architecture on its own (BM_Unpack11Arch/<name>). Bytes/s counts the packed input bytes.
#include <benchmark/benchmark.h>

#include <random>
#include <string>
#include <vector>

#include "kernels/detail/packed_depth_kernel.hpp"
#include "kernels/packed_depth.hpp"

namespace ok = orthoflow::kernels;

namespace {

constexpr std::size_t FRAME_PIXELS = 640 * 480;

std::vector<std::uint8_t> random_frame(unsigned bits) {
  std::mt19937 rng(1);
  std::vector<std::uint8_t> packed(ok::packed_bytes(FRAME_PIXELS, bits));
  for (auto& b : packed) b = static_cast<std::uint8_t>(rng());
  return packed;
}

template <unsigned BITS, bool SIMD>
void BM_Unpack(benchmark::State& state) {
  const std::vector<std::uint8_t> packed = random_frame(BITS);
  std::vector<std::uint16_t> out(FRAME_PIXELS);
  for (auto _ : state) {
    if constexpr (BITS == 11) {
      SIMD ? ok::unpack_11bit(packed, out) : ok::unpack_11bit_scalar(packed, out);
    } else {
      SIMD ? ok::unpack_10bit(packed, out) : ok::unpack_10bit_scalar(packed, out);
    }
    benchmark::DoNotOptimize(out.data());
    benchmark::ClobberMemory();
  }
  state.SetBytesProcessed(static_cast<std::int64_t>(state.iterations() * packed.size()));
  state.SetLabel(SIMD ? ok::simd_arch_name() : "scalar");
}
BENCHMARK(BM_Unpack<11, false>)->Name("BM_Unpack11Bit_scalar");
BENCHMARK(BM_Unpack<11, true>)->Name("BM_Unpack11Bit_simd");
BENCHMARK(BM_Unpack<10, false>)->Name("BM_Unpack10Bit_scalar");
BENCHMARK(BM_Unpack<10, true>)->Name("BM_Unpack10Bit_simd");

// Every architecture this CPU runs, so the SSE2 / AVX2 tiers are measured on an AVX-512 machine.
void register_per_arch() {
  ok::for_each_available_arch([](auto arch) {
    const std::string name = std::string("BM_Unpack11Arch/") + decltype(arch)::name();
    benchmark::RegisterBenchmark(name.c_str(), [arch](benchmark::State& state) {
      const std::vector<std::uint8_t> packed = random_frame(11);
      std::vector<std::uint16_t> out(FRAME_PIXELS);
      for (auto _ : state) {
        ok::detail::UnpackKernel<11>{}(arch, packed, out);
        benchmark::DoNotOptimize(out.data());
        benchmark::ClobberMemory();
      }
      state.SetBytesProcessed(static_cast<std::int64_t>(state.iterations() * packed.size()));
    });
  });
}

}  // namespace

int main(int argc, char** argv) {
  register_per_arch();
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
