#pragma once
// The safety monitor's property test (issue 49, item 6; docs/SAFETY.md): a generator of command
// sequences on the simulated JACO with physics, in lock step on simulated time. Each sequence puts
// random keep-outs (a table under the hand, boxes near the arm) around the arm, then for about 1.5
// simulated seconds issues random commands of every mode (joint and Cartesian moves, velocity
// streams ramped or jumped, fingers, HOME / RETRACT, stops, emergency stops and resets, a held
// object), feeds the watchdog at a random cadence and injects random link faults (a silent
// period, garbage and corrupt replies). After every cycle it judges the simulator's true state:
// no link, finger or held object inside a keep-out or outside the workspace, no joint past its
// limit, and every stop at rest within the documented bound. The choices come from a Chooser: a
// seeded generator (the gtest) or a fuzzer's bytes (fuzz_arm_sequence).
#include <cstddef>
#include <cstdint>
#include <iosfwd>
#include <span>
#include <string>

namespace orthoflow::test {

/// @brief Where the sequence's choices come from.
class Chooser {
 public:
  virtual ~Chooser() = default;
  /// @brief A value in [0, n). @pre n > 0.
  virtual std::uint32_t below(std::uint32_t n) = 0;
  /// @brief A value in [lo, hi].
  double uniform(double lo, double hi) {
    return lo + (hi - lo) * below(1U << 20) / double(1U << 20);
  }
  bool chance(double p) { return below(1000) < static_cast<std::uint32_t>(p * 1000.0); }
};

/// @brief splitmix64, seeded: the same seed gives the same sequence on every machine.
class SeededChooser final : public Chooser {
 public:
  explicit SeededChooser(std::uint64_t seed) : state_(seed) {}
  std::uint32_t below(std::uint32_t n) override;

 private:
  std::uint64_t state_;
};

/// @brief A fuzzer's bytes, two per choice; zeros once they run out.
class ByteChooser final : public Chooser {
 public:
  explicit ByteChooser(std::span<const std::uint8_t> bytes) : bytes_(bytes) {}
  std::uint32_t below(std::uint32_t n) override;

 private:
  std::span<const std::uint8_t> bytes_;
  std::size_t at_ = 0;
};

/// @brief What a sequence did and whether the properties held.
struct SequenceResult {
  bool ok = true;
  bool unopened = false;  ///< the driver refused to open a link garbled at every start
  std::string failure;    ///< the first property broken, with the cycle
  int cycles = 0;
  double worst_clearance_m = 1e9;  ///< the true body's smallest clearance over the sequence
  std::uint64_t monitor_stops = 0;
  std::uint64_t refused = 0;
  std::uint64_t stops = 0;          ///< stops and emergency stops requested
  std::int64_t worst_stop_ns = 0;   ///< longest request-to-rest of a stop, simulated time
  std::uint64_t monitor_nodes = 0;  ///< stretches the monitor examined, summed over the cycles
};

/// @brief Runs one sequence of about @p cycles control cycles with @p choose's choices.
/// With @p trace, every cycle's command, state and true clearance is written there (to debug a
/// seed).
[[nodiscard]] SequenceResult run_arm_sequence(Chooser& choose, int cycles = 150,
                                              std::ostream* trace = nullptr);

/// @brief The bound a stop is judged by: from the request, the host's period to send it and the
/// simulated arm's command latency (meanwhile it may still speed up from @p speed_deg_s at its
/// acceleration), braking from there at its deceleration, and three DSP cycles (the packet taken,
/// the last braking step, the transfer).
[[nodiscard]] std::int64_t stop_bound_ns(double speed_deg_s);

}  // namespace orthoflow::test
