// The shipped two-process example (graphs/sensor.yaml -> graphs/perception.yaml) under a RouDi that
// dies (issue 16, item 12): both `graph run` processes stop within a bounded time, name RouDi and
// exit 22, and the publisher does not claim samples it did not send. `ipc run` runs the same
// graphs. Own RouDi (pools from `orthoflow ipc config`) in a private mount namespace, as in
// ipc_cli_test.cpp.
#include <gtest/gtest.h>
#include <signal.h>

#include <cstdio>
#include <string>
#include <thread>

#include "tests/ipc/roudi_sandbox.hpp"

namespace orthoflow::tests {
namespace {

using namespace std::chrono_literals;
using Clock = std::chrono::steady_clock;

const std::string GRAPHS = ORTHOFLOW_SOURCE_DIR "/graphs/";

#define RUN_ISOLATED(...)                                   \
  do {                                                      \
    const Outcome outcome = run_isolated(__VA_ARGS__, 30s); \
    if (outcome.skipped) GTEST_SKIP() << outcome.reason;    \
    EXPECT_EQ(outcome.failures, "");                        \
  } while (false)

// Value of "<key> N" on the line of `text` that starts with `line_start`, or -1.
long long counter(const std::string& text, const std::string& line_start, const std::string& key) {
  for (const std::string& line : lines_with(text, line_start)) {
    if (line.rfind(line_start, 0) != 0) continue;
    const std::size_t at = line.find(" " + key + " ");
    if (at == std::string::npos) return -1;
    return std::stoll(line.substr(at + key.size() + 2));
  }
  return -1;
}

// RouDi with pools sized for both shipped graphs, as scripts/ipc_demo.sh starts it.
pid_t start_roudi_for_the_example(Sandbox& box) {
  const ProcResult config =
      box.wait(box.spawn_orthoflow(
                   "config", {"ipc", "config", GRAPHS + "sensor.yaml", GRAPHS + "perception.yaml"}),
               10s);
  box.check(config.exit_code == 0, "ipc config of the shipped graphs", config);
  if (config.exit_code != 0) return -1;
  return box.start_roudi("/tmp/config.out");
}

TEST(IpcGraphs, RouDiKilledUnderTheShippedExampleEndsBothRunsWithExit22) {
  RUN_ISOLATED([](Sandbox& box) {
    const pid_t roudi = start_roudi_for_the_example(box);
    if (roudi < 0) return;
    const pid_t perception =
        box.spawn_orthoflow("perception", {"graph", "run", GRAPHS + "perception.yaml"});
    std::this_thread::sleep_for(1s);  // let the subscriber register before the first frame
    const pid_t sensor = box.spawn_orthoflow("sensor", {"graph", "run", GRAPHS + "sensor.yaml"});
    std::this_thread::sleep_for(2s);  // about 60 of the 300 frames
    ::kill(roudi, SIGKILL);
    const auto killed = Clock::now();
    const ProcResult s = box.wait(sensor, 5s), p = box.wait(perception, 5s);
    const double after = std::chrono::duration<double>(Clock::now() - killed).count();
    std::fprintf(stderr, "both runs ended %.3f s after RouDi was killed\n", after);
    box.check(after < 2.0,
              "both runs end within 2 s of the kill (" + std::to_string(after) + " s)");
    for (const ProcResult* run : {&s, &p}) {
      box.check(
          run->exit_code == 22 && run->err.find("RouDi lost while running") != std::string::npos,
          "graph run exits 22 and names RouDi", *run);
      box.check(run->out.find("(RouDi lost, all in-flight frames drained)") != std::string::npos,
                "the summary says why the run stopped", *run);
    }
    const long long sent = counter(s.out, "ipc publish ", "samples");
    const long long unsent = counter(s.out, "ipc publish ", "unpublished");
    box.check(sent > 0 && sent < 300 && unsent >= 0 && sent + unsent < 300,
              "the sensor claims only the frames it sent before the loss (" + std::to_string(sent) +
                  " sent, " + std::to_string(unsent) + " unpublished)",
              s);
    box.check(counter(p.out, "ipc frames ", "samples") > 0, "perception received frames", p);
  });
}

TEST(IpcGraphs, IpcRunRunsTheShippedSensorGraph) {
  RUN_ISOLATED([](Sandbox& box) {
    if (start_roudi_for_the_example(box) < 0) return;
    const ProcResult r = box.wait(
        box.spawn_orthoflow("ipc_run", {"ipc", "run", GRAPHS + "sensor.yaml", "--frames", "10"}),
        10s);
    box.check(r.exit_code == 0 && r.out.find("frame limit reached") != std::string::npos &&
                  counter(r.out, "ipc publish ", "samples") == 10 &&
                  counter(r.out, "ipc publish ", "unpublished") == 0,
              "ipc run graphs/sensor.yaml --frames 10: 10 published, exit 0", r);
  });
}

}  // namespace
}  // namespace orthoflow::tests
