// `orthoflow task run|start|stop|status`: a table task on a live arm (issue 21, item 5).
// - `task run` opens the arm (USB, or the simulated JACO with --sim), takes a running graph's
// object
//   lists (`orthoflow run --ipc-learning --robot-frames ...` publishes them on
//   orthoflow/<graph>/objects), streams the arm's state (what the hand holds included) on
//   orthoflow/jaco/state for that graph's robot-body filter, and waits for commands on
//   orthoflow/<graph>/task_commands; --start starts a task at once. Ctrl-C or SIGTERM stops the
//   task (the running job backs away) before it exits.
// - `task start clear_table|serve_a_meal`, `task stop` send one command and wait for its answer on
//   orthoflow/<graph>/task_status; `task status` prints the newest status.
// graphs/sessions/live_table_task.hpp runs the task; docs/MANIPULATION.md section 5 tells the whole
// story. This file holds the options; the iceoryx plumbing is in cmd_task_live_ipc.cpp, `task run`
// in cmd_task_live_run.cpp, `task start|stop|status` in cmd_task_live_send.cpp
// (apps/task_live_cli.hpp).
#include <iostream>
#include <memory>
#include <optional>
#include <string>

#include <CLI/CLI.hpp>

#include "apps/arm_cli.hpp"
#include "apps/commands.hpp"
#include "apps/option_checks.hpp"
#include "apps/perceived_scene.hpp"
#include "apps/task_live_cli.hpp"
#include "graphs/channels/task_payloads.hpp"
#include "manipulation/table_task_runner.hpp"

namespace orthoflow::apps {

namespace task_live_cli {

[[noreturn]] void fail(const std::string& what, int code) {
  std::cerr << "orthoflow task: " << what << '\n';
  throw CLI::RuntimeError(code);
}

graphs::TaskCommand start_command(const LiveArgs& a) {
  graphs::TaskCommand c;
  c.kind = graphs::TaskCommand::Kind::START;
  if (!manipulation::parse_table_task(a.start, c.task))
    fail("unknown task '" + a.start + "' (clear_table or serve_a_meal)", EXIT_USAGE);
  c.bring = a.bring;
  if (c.task == manipulation::TableTaskKind::SERVE_A_MEAL && c.bring.empty())
    fail("serve_a_meal needs --bring CATEGORY[,...]", EXIT_USAGE);
  if (c.bring.size() > graphs::TASK_MAX_BRING)
    fail("at most " + std::to_string(graphs::TASK_MAX_BRING) + " categories to bring", EXIT_USAGE);
  return c;
}

}  // namespace task_live_cli

namespace {

using namespace task_live_cli;

void add_area_options(CLI::App* cmd, const std::shared_ptr<LiveArgs>& a) {
  cmd->add_option("--area", a->area,
                  "clear_table: the placing area X0,Y0,X1,Y1 on the table, base frame (m; default "
                  "0.20,-0.50,0.56,-0.15, the synthetic robot frames')")
      ->type_name("X0,Y0,X1,Y1")
      ->expected(4)
      ->delimiter(',')
      ->check(table_coordinate());
  cmd->add_option("--keep", a->keep, "clear_table: table items that stay (default plate)")
      ->delimiter(',');
  cmd->add_option("--user-place", a->user_place,
                  "serve_a_meal: the user's place X,Y, base frame (m; default -0.35,-0.50)")
      ->type_name("X,Y")
      ->expected(2)
      ->delimiter(',')
      ->check(table_coordinate());
}

}  // namespace

void add_live_task_commands(CLI::App* task) {
  auto a = std::make_shared<LiveArgs>();
  auto* run = task->add_subcommand(
      "run",
      "run table tasks on the arm from a running graph's objects (orthoflow run --ipc-learning "
      "--robot-frames F): waits for `task start`, or --start; Ctrl-C stops the task, then exits");
  arm_cli::add_common_options(run, a->arm);
  run->add_option("--robot-frames", a->frames, "robot frames file (base_from_camera)")->required();
  run->add_option("--graph", a->graph, "the graph's name in its topics (default tabletop)");
  run->add_option("--start", a->start, "start this task at once: clear_table or serve_a_meal");
  run->add_option("--bring", a->bring, "with --start serve_a_meal: the categories, in order")
      ->transform(composed_label())
      ->delimiter(',');
  add_area_options(run, a);
  run->add_option("--max-perception-age-ms", a->perception_age_ms,
                  "the stale-perception interlock: a job stops when the newest objects are older "
                  "than this (from the frame's exposure; default 300)")
      ->check(CLI::Range(50.0, 2000.0));
  run->add_option("--seconds", a->seconds, "stop the task and exit after this long (0: never)")
      ->check(CLI::Range(0.0, 86400.0));
  run->add_flag("--exit-when-done", a->exit_when_done,
                "with --start: exit once the task has ended and the arm is still");
  run->callback([a] {
    if (a->exit_when_done && a->start.empty()) fail("--exit-when-done needs --start", EXIT_USAGE);
    a->json = a->arm->json;  // --json (the arm options'): the report as one JSON object
    run_live(*a);
  });

  auto* start = task->add_subcommand("start", "start a task on a running `orthoflow task run`");
  start->add_option("task", a->start, "clear_table or serve_a_meal")->required();
  start->add_option("--bring", a->bring, "serve_a_meal: the categories to bring, in order")
      ->transform(composed_label())
      ->delimiter(',');
  for (CLI::App* sub :
       {start, task->add_subcommand("stop", "stop the running task (it backs away)"),
        task->add_subcommand("status", "the task's newest status")}) {
    sub->add_option("--graph", a->graph, "the graph's name in its topics (default tabletop)");
    sub->add_option("--timeout", a->timeout_s, "wait this long for the answer (s, default 5)")
        ->check(CLI::Range(0.1, 600.0));
    sub->add_flag("--json", a->json, "the answer as JSON");
  }
  start->callback([a] { send_command(*a, start_command(*a)); });
  task->get_subcommand("stop")->callback([a] {
    graphs::TaskCommand c;
    c.kind = graphs::TaskCommand::Kind::STOP;
    send_command(*a, c);
  });
  task->get_subcommand("status")->callback([a] { send_command(*a, std::nullopt); });
}

}  // namespace orthoflow::apps
