// The JACO kinematics' cost per call (drivers/jaco_kinematics.hpp): forward kinematics, and the
// IK from a seed near the answer (a control loop: 2 degrees, and the tests' 20 degrees), from a
// far seed (90 degrees: restarts usually run), and for a target no start reaches (worst case).
#include <benchmark/benchmark.h>

#include <cstddef>
#include <random>
#include <vector>

#include "drivers/jaco_kinematics.hpp"

namespace {

using namespace orthoflow::drivers::jaco;

struct Case {
  Eigen::Isometry3d target;
  JointAngles seed;
};

// 256 random reachable targets with seeds perturbed by up to @p spread_deg per joint.
std::vector<Case> make_cases(double spread_deg) {
  const JointLimits limits = jaco_joint_limits();
  std::mt19937 rng(1);
  std::uniform_real_distribution<double> perturb(-spread_deg, spread_deg);
  std::vector<Case> cases;
  for (int n = 0; n < 256; ++n) {
    JointAngles q{};
    for (std::size_t i = 0; i < 6; ++i) {
      const double lower = limits.lower[i] > -360.0 ? limits.lower[i] : -360.0;
      const double upper = limits.upper[i] < 360.0 ? limits.upper[i] : 360.0;
      q[i] = std::uniform_real_distribution<double>(lower, upper)(rng);
    }
    Case c{forward_kinematics(q), q};
    for (double& v : c.seed) v += perturb(rng);
    cases.push_back(c);
  }
  return cases;
}

void BM_ForwardKinematics(benchmark::State& state) {
  const std::vector<Case> cases = make_cases(0.0);
  std::size_t k = 0;
  for (auto _ : state) {
    benchmark::DoNotOptimize(forward_kinematics(cases[k++ % cases.size()].seed));
  }
}
BENCHMARK(BM_ForwardKinematics);

void BM_InverseKinematics(benchmark::State& state) {
  const std::vector<Case> cases = make_cases(static_cast<double>(state.range(0)));
  const JointLimits limits = jaco_joint_limits();
  std::size_t k = 0, solved = 0, calls = 0;
  for (auto _ : state) {
    const Case& c = cases[k++ % cases.size()];
    const auto result = inverse_kinematics(c.target, c.seed, limits);
    solved += result.has_value() ? 1 : 0;
    ++calls;
    benchmark::DoNotOptimize(result);
  }
  state.counters["solved"] = static_cast<double>(solved) / static_cast<double>(calls);
}
BENCHMARK(BM_InverseKinematics)->Arg(2)->Arg(20)->Arg(90)->Unit(benchmark::kMicrosecond);

void BM_InverseKinematicsUnreachable(benchmark::State& state) {
  const JointAngles home = {275, 167, 57, 240, 83, 75};
  Eigen::Isometry3d target = forward_kinematics(home);
  target.translation() = Eigen::Vector3d(0.0, -0.93, 0.2755);  // inside the reach sphere only
  const JointLimits limits = jaco_joint_limits();
  for (auto _ : state) benchmark::DoNotOptimize(inverse_kinematics(target, home, limits));
}
BENCHMARK(BM_InverseKinematicsUnreachable)->Unit(benchmark::kMicrosecond);

}  // namespace

BENCHMARK_MAIN();
