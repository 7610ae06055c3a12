// Drives the safety monitor's property-test generator (tests/drivers/jaco/arm_sequence.hpp) with a
// fuzzer's bytes instead of a seed: every choice (keep-outs, faults, commands of every mode,
// keep-alive cadence, stops, held objects) comes from the input. Any sequence in which the true
// simulated arm enters a keep-out, leaves the workspace, passes a joint limit or does not stop in
// its bound aborts with the property that broke.
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <span>

#include "tests/drivers/jaco/arm_sequence.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  orthoflow::test::ByteChooser choose(std::span<const std::uint8_t>(data, size));
  const orthoflow::test::SequenceResult r = orthoflow::test::run_arm_sequence(choose, 60);
  if (!r.ok) {
    std::fprintf(stderr, "fuzz_arm_sequence: %s\n", r.failure.c_str());
    std::abort();
  }
  return 0;
}
