// Results out across processes: `orthoflow run --publish-objects` sends every frame's objects on
// orthoflow/tabletop/objects, and `orthoflow ipc echo --type objects` in another process reads them
// (ObjectListPayload version 2); a RouDi killed under the run ends it with exit 22. Own RouDi in a
// private mount namespace, as in ipc_cli_test.cpp.
#include <gtest/gtest.h>
#include <signal.h>

#include <chrono>
#include <string>
#include <thread>

#include "tests/ipc/roudi_sandbox.hpp"

namespace orthoflow::tests {
namespace {

using namespace std::chrono_literals;

TEST(IpcObjects, RunPublishesEveryFramesObjectsToAnotherProcess) {
  const Outcome outcome = run_isolated(
      [](Sandbox& box) {
        if (box.start_roudi() < 0) return;
        const pid_t echo = box.spawn_orthoflow(
            "echo", {"ipc", "echo", "orthoflow/tabletop/objects", "--type", "objects", "--count",
                     "20", "--depth", "64", "--timeout-ms", "8000"});
        const pid_t run = box.spawn_orthoflow(
            "run", {"run", "--frames", "60", "--rate", "30", "--publish-objects"});
        const ProcResult r = box.wait(run, 30s), e = box.wait(echo, 30s);
        box.check(r.exit_code == 0, "run --publish-objects exits 0", r);
        box.check(e.exit_code == 0, "echo exits 0", e);
        box.check(e.out.find("type objects frame ") != std::string::npos, "echo reads object lists",
                  e);
        box.check(e.out.find("  track 1 label ") != std::string::npos,
                  "the lists carry tracked objects", e);
        box.check(e.out.find("rejected 0") != std::string::npos,
                  "no list is rejected (type and version match)", e);
      },
      40s);
  if (outcome.skipped) GTEST_SKIP() << outcome.reason;
  EXPECT_EQ(outcome.failures, "");
}

// A RouDi killed under `run --publish-objects` ends the run within a bounded time with exit 22
// naming RouDi, its summary still printed (issue 16, item 12, for the product command).
TEST(IpcObjects, RouDiKilledUnderRunPublishObjectsEndsItWithExit22) {
  const Outcome outcome = run_isolated(
      [](Sandbox& box) {
        const pid_t roudi = box.start_roudi();
        if (roudi < 0) return;
        const pid_t run = box.spawn_orthoflow(
            "run", {"run", "--frames", "3000", "--rate", "30", "--publish-objects"});
        std::this_thread::sleep_for(1500ms);
        ::kill(roudi, SIGKILL);
        const auto killed = std::chrono::steady_clock::now();
        const ProcResult r = box.wait(run, 10s);
        const double after =
            std::chrono::duration<double>(std::chrono::steady_clock::now() - killed).count();
        box.check(after < 2.0, "run ends within 2 s of the kill (" + std::to_string(after) + " s)");
        box.check(r.exit_code == 22 && r.err.find("RouDi lost") != std::string::npos,
                  "run --publish-objects exits 22 and names RouDi", r);
        box.check(r.out.find("orthoflow run: graph") != std::string::npos,
                  "the summary is still printed", r);
      },
      40s);
  if (outcome.skipped) GTEST_SKIP() << outcome.reason;
  EXPECT_EQ(outcome.failures, "");
}

}  // namespace
}  // namespace orthoflow::tests
