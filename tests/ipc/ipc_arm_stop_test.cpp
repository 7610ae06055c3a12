// The arm's stop from another process over iceoryx (graphs/services/arm_stop_service.hpp,
// docs/SAFETY.md section 4): `orthoflow arm move --sim` holds the arm and, RouDi running, listens
// on orthoflow/jaco/stop; `orthoflow arm stop --sim` in another process reaches it there, the arm
// halts in place and the stop is latched in the state directory: the next motion is refused until
// `orthoflow arm reset`. Own RouDi and state directory in a private mount namespace.
#include <gtest/gtest.h>
#include <signal.h>

#include <chrono>
#include <nlohmann/json.hpp>
#include <string>
#include <thread>

#include "tests/ipc/roudi_sandbox.hpp"

namespace orthoflow::tests {
namespace {

using namespace std::chrono_literals;

TEST(IpcArmStop, ASecondProcessStopsTheHolderOverIceoryxAndTheStopIsLatched) {
  const Outcome outcome = run_isolated(
      [](Sandbox& box) {
        if (box.start_roudi() < 0) return;
        const pid_t move = box.spawn_orthoflow("move", {"arm", "move", "--sim", "--speed", "0.3",
                                                        "--joints", "355,167.5,57.5,240,82.5,75"});
        std::this_thread::sleep_for(1500ms);
        const ProcResult stop =
            box.wait(box.spawn_orthoflow("stop", {"arm", "stop", "--sim", "--json"}), 20s);
        box.check(stop.exit_code == 0, "arm stop exits 0", stop);
        const auto j = nlohmann::json::parse(stop.out, nullptr, false);
        box.check(j.is_object() && j.value("via", std::string()) == "iceoryx" &&
                      j.value("was_moving", false) && j.value("holder_pid", 0) == move &&
                      j.value("holder", std::string()) == "orthoflow arm move",
                  "the holder answered over iceoryx: it was moving", stop);
        box.check(j.is_object() && j.value("request_to_halt_ms", 1e9) < 100.0,
                  "halted within 100 ms of the request", stop);
        const ProcResult m = box.wait(move, 20s);
        box.check(m.exit_code == 1 && m.err.find("orthoflow arm stop") != std::string::npos &&
                      m.err.find("latched") != std::string::npos,
                  "the move ends: stopped by `arm stop`, latched", m);
        const ProcResult again = box.wait(
            box.spawn_orthoflow("again",
                                {"arm", "move", "--sim", "--joints", "280,167.5,57.5,240,82.5,75"}),
            20s);
        box.check(again.exit_code == 1 && again.err.find("latched") != std::string::npos,
                  "the next holder refuses to move while latched", again);
        const ProcResult reset =
            box.wait(box.spawn_orthoflow("reset", {"arm", "reset", "--sim"}), 20s);
        box.check(reset.exit_code == 0 && reset.out.find("cleared") != std::string::npos,
                  "a person's reset clears it", reset);
      },
      60s);
  if (outcome.skipped) GTEST_SKIP() << outcome.reason;
  EXPECT_EQ(outcome.failures, "");
}

}  // namespace
}  // namespace orthoflow::tests
