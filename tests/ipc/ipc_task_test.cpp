// A table task on a live arm across processes (issue 21, item 5): `orthoflow task run --sim` takes
// the object lists of `orthoflow run --ipc-learning --robot-frames ...` running in another process,
// streams the arm's state back to that graph's robot-body filter, and answers the commands that
// `orthoflow task start|stop|status` send on the task command channel (graphs/task_payloads.hpp).
// A SIGTERM stops the task and the process exits with its report. Own RouDi in a private mount
// namespace (roudi_sandbox.hpp).
#include <gtest/gtest.h>
#include <signal.h>

#include <chrono>
#include <string>
#include <thread>

#include <nlohmann/json.hpp>

#include "tests/ipc/roudi_sandbox.hpp"

namespace orthoflow::tests {
namespace {

using namespace std::chrono_literals;

constexpr const char* FRAMES = ORTHOFLOW_SOURCE_DIR "/config/robot_frames_synthetic.yaml";

TEST(IpcTask, TasksAreStartedAndStoppedFromAnotherProcessOnTheGraphsObjects) {
  const Outcome outcome = run_isolated(
      [](Sandbox& box) {
        if (box.start_roudi() < 0) return;
        // Nothing runs yet: a start finds no task process and says so.
        const ProcResult alone = box.wait(
            box.spawn_orthoflow("alone", {"task", "start", "clear_table", "--timeout", "1"}), 20s);
        box.check(alone.exit_code == 31, "a start with no task process exits 31", alone);
        const pid_t task = box.spawn_orthoflow("task", {"task", "run", "--sim", "--robot-frames",
                                                        FRAMES, "--seconds", "120", "--json"});
        box.check(
            box.wait_for_output(task, "task: commands on orthoflow/tabletop/task_commands", 30s),
            "the task process says where it takes commands");
        // Before the graph runs, a start is refused: no fresh objects.
        const ProcResult early =
            box.wait(box.spawn_orthoflow("early", {"task", "start", "clear_table", "--json"}), 20s);
        box.check(early.exit_code == 30, "a start without objects exits 30", early);
        box.check(early.out.find("no fresh objects from the graph") != std::string::npos,
                  "and says why", early);
        const pid_t run = box.spawn_orthoflow("run", {"run", "--frames", "9000", "--rate", "30",
                                                      "--ipc-learning", "--robot-frames", FRAMES});
        box.check(box.wait_for_output(run, "learning commands on", 30s), "the graph runs");
        std::this_thread::sleep_for(2s);  // object lists flow
        const ProcResult bad = box.wait(
            box.spawn_orthoflow("bad", {"task", "start", "serve_a_meal", "--bring", "pizza"}), 20s);
        box.check(bad.exit_code == 30, "serve_a_meal of a category nobody taught exits 30", bad);
        box.check(bad.out.find("nobody taught the category 'pizza'") != std::string::npos,
                  "and names it", bad);
        const ProcResult start =
            box.wait(box.spawn_orthoflow("start", {"task", "start", "clear_table", "--json"}), 20s);
        box.check(start.exit_code == 0, "the start is answered", start);
        const auto started = nlohmann::json::parse(start.out, nullptr, false);
        box.check(!started.is_discarded() && started["answer"] == "started" &&
                      started["task"] == "clear_table",
                  "answered: started clear_table", start);
        const ProcResult status =
            box.wait(box.spawn_orthoflow("status", {"task", "status", "--json"}), 20s);
        box.check(status.exit_code == 0 && status.out.find("clear_table") != std::string::npos,
                  "the status names the task", status);
        const ProcResult stop =
            box.wait(box.spawn_orthoflow("stop", {"task", "stop", "--json"}), 20s);
        // The task may have ended already (nothing the learner knows to move): then the stop is
        // refused with that reason; else it is taken.
        box.check(stop.out.find("\"answer\":\"stopping\"") != std::string::npos ||
                      stop.out.find("no task is running") != std::string::npos,
                  "the stop is answered", stop);
        ::kill(task, SIGTERM);
        const ProcResult t = box.wait(task, 60s);
        ::kill(run, SIGTERM);
        const ProcResult r = box.wait(run, 60s);
        box.check(t.exit_code == 0, "the task process exits 0 on SIGTERM", t);
        const std::size_t line = t.out.rfind("\n{");  // the last line: the JSON report
        const auto report = nlohmann::json::parse(
            line == std::string::npos ? std::string() : t.out.substr(line + 1), nullptr, false);
        box.check(!report.is_discarded() && report["exit"] == "stopped" &&
                      report["object_lists"].get<std::uint64_t>() > 30 &&
                      report["commands"].get<std::uint64_t>() >= 4 &&
                      report["rejected"].get<std::uint64_t>() == 0 &&
                      report["report"]["task"] == "clear_table",
                  "its report: stopped, the graph's object lists, every command, none rejected", t);
        // The graph's body filter used the task process's arm states.
        box.check(r.out.find("frames_filtered 0,") == std::string::npos &&
                      r.out.find("frames_filtered") != std::string::npos,
                  "the graph filtered frames with the arm's streamed state", r);
      },
      240s);
  if (outcome.skipped) GTEST_SKIP() << outcome.reason;
  EXPECT_EQ(outcome.failures, "");
}

}  // namespace
}  // namespace orthoflow::tests
