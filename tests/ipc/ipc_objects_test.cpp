// Results out across processes: `orthoflow run --publish-objects` sends every frame's objects on
// orthoflow/tabletop/objects, and `orthoflow ipc echo --type objects` in another process reads them
// (ObjectListPayload version 2). Own RouDi in a private mount namespace, as in ipc_cli_test.cpp.
#include <gtest/gtest.h>

#include <string>

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

}  // namespace
}  // namespace orthoflow::tests
