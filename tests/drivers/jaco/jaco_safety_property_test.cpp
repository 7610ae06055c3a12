// The safety monitor's property test (issue 49, item 6; docs/SAFETY.md): seeded random command
// sequences of every mode, with faults and stops, on the simulated arm with physics
// (arm_sequence.hpp). 10,000 sequences in the release build, 1,000 under the sanitizers; not under
// qemu (label qemu_heavy). Every property must hold in every sequence; the first broken one is
// reported with its seed, which reruns it alone (ORTHOFLOW_ARM_SEED=N).
#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cstdlib>
#include <iostream>

#include "tests/drivers/jaco/arm_sequence.hpp"

namespace orthoflow::test {
namespace {

#if defined(__SANITIZE_ADDRESS__) || defined(__SANITIZE_THREAD__)
constexpr int SEQUENCES = 1000;
#else
constexpr int SEQUENCES = 10000;
#endif

TEST(JacoSafetyProperty, NoSequenceOfCommandsGetsPastTheMonitor) {
  int first = 1, count = SEQUENCES;
  if (const char* one = std::getenv("ORTHOFLOW_ARM_SEED")) {
    first = std::atoi(one);
    count = 1;
  }
  if (const char* n = std::getenv("ORTHOFLOW_ARM_SEQUENCES")) count = std::max(1, std::atoi(n));
  const auto t0 = std::chrono::steady_clock::now();
  int failures = 0, unopened = 0;
  std::uint64_t cycles = 0, stops = 0, monitor_stops = 0, refused = 0, nodes = 0;
  std::int64_t worst_stop = 0;
  double worst_clearance = 1e9;
  for (int seed = first; seed < first + count; ++seed) {
    SeededChooser choose(static_cast<std::uint64_t>(seed));
    const SequenceResult r = run_arm_sequence(
        choose, 150, count == 1 && std::getenv("ORTHOFLOW_ARM_TRACE") ? &std::cout : nullptr);
    cycles += static_cast<std::uint64_t>(r.cycles);
    unopened += r.unopened ? 1 : 0;
    stops += r.stops;
    monitor_stops += r.monitor_stops;
    refused += r.refused;
    nodes += r.monitor_nodes;
    worst_stop = std::max(worst_stop, r.worst_stop_ns);
    worst_clearance = std::min(worst_clearance, r.worst_clearance_m);
    if (!r.ok && ++failures <= 5) ADD_FAILURE() << "seed " << seed << ": " << r.failure;
  }
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  // The numbers docs/SAFETY.md reports (rerun: this test's output).
  std::cout << "property: " << count << " sequences, " << cycles << " cycles, " << failures
            << " violations, " << unopened << " links refused at open; " << stops
            << " stops (worst request to rest " << static_cast<double>(worst_stop) / 1e6
            << " ms simulated), " << monitor_stops << " monitor stops, " << refused
            << " refusals; true clearance at least " << worst_clearance * 1e3 << " mm; "
            << static_cast<double>(nodes) / double(cycles) << " monitor stretches per cycle; "
            << seconds << " s\n";
  EXPECT_EQ(failures, 0);
  EXPECT_GT(monitor_stops + refused, 0U);  // the generator does reach the limits
  EXPECT_LT(unopened, count / 20 + 1);     // and most sequences do run
}

}  // namespace
}  // namespace orthoflow::test
