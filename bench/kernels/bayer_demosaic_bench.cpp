// Kinect v1 GRBG demosaic on one 640x480 frame: the dispatched SIMD kernel against the scalar
// twin, for the RGB24 and the packed 0xFFRRGGBB outputs, and each compiled architecture on its own
// (BM_DemosaicArch/<form>/<name>). Bytes/s counts the mosaic input bytes (one per pixel).
#include <benchmark/benchmark.h>

#include <random>
#include <string>
#include <vector>

#include "kernels/bayer_demosaic.hpp"
#include "kernels/detail/bayer_demosaic_kernel.hpp"

namespace ok = orthoflow::kernels;
namespace od = orthoflow::kernels::detail;

namespace {

constexpr std::uint32_t WIDTH = 640;
constexpr std::uint32_t HEIGHT = 480;
constexpr std::size_t PIXELS = std::size_t{WIDTH} * HEIGHT;

std::vector<std::uint8_t> random_mosaic() {
  std::mt19937 rng(1);
  std::vector<std::uint8_t> bayer(PIXELS);
  for (auto& b : bayer) b = static_cast<std::uint8_t>(rng());
  return bayer;
}

template <od::DemosaicForm FORM, class Run>
void run_frames(benchmark::State& state, Run run) {
  constexpr std::size_t PER_PIXEL = FORM == od::DemosaicForm::RGB24 ? 3 : 1;
  const std::vector<std::uint8_t> bayer = random_mosaic();
  std::vector<od::DemosaicPixel<FORM>> out(PER_PIXEL * PIXELS);
  for (auto _ : state) {
    run(bayer, out);
    benchmark::DoNotOptimize(out.data());
    benchmark::ClobberMemory();
  }
  state.SetBytesProcessed(static_cast<std::int64_t>(state.iterations() * PIXELS));
}

template <bool SIMD>
void BM_DemosaicRgb24(benchmark::State& state) {
  run_frames<od::DemosaicForm::RGB24>(state, [](const auto& bayer, auto& out) {
    SIMD ? ok::demosaic_grbg(bayer, WIDTH, HEIGHT, out)
         : ok::demosaic_grbg_scalar(bayer, WIDTH, HEIGHT, out);
  });
  state.SetLabel(SIMD ? ok::simd_arch_name() : "scalar");
}
template <bool SIMD>
void BM_DemosaicPacked(benchmark::State& state) {
  run_frames<od::DemosaicForm::PACKED>(state, [](const auto& bayer, auto& out) {
    SIMD ? ok::demosaic_grbg_packed(bayer, WIDTH, HEIGHT, out)
         : ok::demosaic_grbg_packed_scalar(bayer, WIDTH, HEIGHT, out);
  });
  state.SetLabel(SIMD ? ok::simd_arch_name() : "scalar");
}
BENCHMARK(BM_DemosaicRgb24<false>)->Name("BM_DemosaicRgb24_scalar");
BENCHMARK(BM_DemosaicRgb24<true>)->Name("BM_DemosaicRgb24_simd");
BENCHMARK(BM_DemosaicPacked<false>)->Name("BM_DemosaicPacked_scalar");
BENCHMARK(BM_DemosaicPacked<true>)->Name("BM_DemosaicPacked_simd");

void BM_Mosaic(benchmark::State& state) {
  std::vector<std::uint8_t> rgb(3 * PIXELS), bayer(PIXELS);
  std::mt19937 rng(2);
  for (auto& b : rgb) b = static_cast<std::uint8_t>(rng());
  for (auto _ : state) {
    ok::mosaic_grbg(rgb, WIDTH, HEIGHT, bayer);
    benchmark::DoNotOptimize(bayer.data());
    benchmark::ClobberMemory();
  }
  state.SetBytesProcessed(static_cast<std::int64_t>(state.iterations() * PIXELS));
}
BENCHMARK(BM_Mosaic);

// Every architecture this CPU runs, so the SSE2 / AVX2 tiers are measured on an AVX-512 machine.
void register_per_arch() {
  ok::for_each_available_arch([](auto arch) {
    const std::string name = decltype(arch)::name();
    benchmark::RegisterBenchmark(
        ("BM_DemosaicArch/rgb24/" + name).c_str(), [arch](benchmark::State& state) {
          run_frames<od::DemosaicForm::RGB24>(state, [arch](const auto& bayer, auto& out) {
            od::DemosaicKernel<od::DemosaicForm::RGB24>{}(arch, bayer, WIDTH, HEIGHT, out);
          });
        });
    benchmark::RegisterBenchmark(
        ("BM_DemosaicArch/packed/" + name).c_str(), [arch](benchmark::State& state) {
          run_frames<od::DemosaicForm::PACKED>(state, [arch](const auto& bayer, auto& out) {
            od::DemosaicKernel<od::DemosaicForm::PACKED>{}(arch, bayer, WIDTH, HEIGHT, out);
          });
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
