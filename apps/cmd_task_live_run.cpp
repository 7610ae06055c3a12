// `orthoflow task run`: the table task on a live arm. It opens the arm, takes a running graph's
// object lists and categories, streams the arm's state, and answers the task commands until a
// signal, the time limit or the task's end; then it stops the arm and prints the report. The
// options are in cmd_task_live.cpp; graphs/sessions/live_table_task.hpp runs the task.
#include <atomic>
#include <chrono>
#include <csignal>
#include <cstdio>
#include <cstring>
#include <iostream>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include "apps/arm_cli.hpp"
#include "apps/commands.hpp"
#include "apps/task_live_cli.hpp"
#include "engine/arm_state_payload.hpp"
#include "engine/ipc_pubsub.hpp"
#include "engine/ipc_runtime.hpp"
#include "graphs/channels/learning_payloads.hpp"
#include "graphs/channels/task_payloads.hpp"
#include "graphs/services/learning_ipc_bridge.hpp"
#include "graphs/sessions/live_table_task.hpp"
#include "graphs/sessions/table_task_session.hpp"
#include "manipulation/robot_frames.hpp"
#include "ui/ui_json.hpp"

namespace orthoflow::apps::task_live_cli {
namespace {

namespace jaco = drivers::jaco;

std::int64_t now_ns() { return Clock::now().time_since_epoch().count(); }

/// Takes at most 64 samples of @p in, handing each one's bytes to @p use (false: it was refused).
/// @return the samples refused, by the subscriber's header check or by @p use.
template <class Use>
std::uint64_t drain(engine::IpcSubscriber& in, const Use& use) {
  std::uint64_t refused = 0;
  for (int n = 0; n < 64; ++n) {
    auto s = in.take();
    if (!s) {
      ++refused;
      continue;
    }
    if (!s->has_value()) break;
    if (!use((*s)->bytes())) ++refused;
  }
  return refused;
}

nlohmann::json report_json(const manipulation::TableTaskRunner& r) {
  nlohmann::json moves = nlohmann::json::array();
  for (const manipulation::MoveRecord& m : r.moves()) {
    moves.push_back({{"track", m.track},
                     {"label", m.label},
                     {"to_m", {m.to.x(), m.to.y()}},
                     {"grasp", m.grasp},
                     {"done", m.done},
                     {"failure", m.failure},
                     {"seconds", m.seconds},
                     {"decisions", m.decisions}});
  }
  nlohmann::json stays = nlohmann::json::array();
  for (const manipulation::StayRecord& s : r.stays())
    stays.push_back({{"track", s.track}, {"label", s.label}, {"reason", s.reason}});
  return {{"task", manipulation::to_string(r.options().task)},
          {"moves", moves},
          {"stays", stays},
          {"stopped", r.stopped()}};
}

manipulation::TableTaskOptions task_options(const LiveArgs& a) {
  const auto frames = manipulation::load_robot_frames(a.frames);
  if (!frames) fail(frames.error(), EXIT_BAD_INPUT);
  manipulation::TableTaskOptions o;
  o.base_from_camera = frames->base_from_camera;
  o.area = {Eigen::Vector2d(std::min(a.area[0], a.area[2]), std::min(a.area[1], a.area[3])),
            Eigen::Vector2d(std::max(a.area[0], a.area[2]), std::max(a.area[1], a.area[3]))};
  o.keep = a.keep;
  o.user_place = Eigen::Vector2d(a.user_place[0], a.user_place[1]);
  // The demo's limits: the same manager on a real arm.
  o.limits = graphs::TableTaskConfig::default_limits();
  o.limits.perception_max_age_ns = static_cast<std::int64_t>(a.perception_age_ms * 1e6);
  // One object list per graph frame (30 Hz live): look for a hidden object 3 s, as the demo does.
  o.look_again_frames = 90;
  if (a.arm->sim) {
    // The simulated JACO of this process has no world between its fingers (the world that moves
    // objects is the graph's, `--source world:SEED`): its hand always closes to the goal.
    o.limits.fingers_must_meet_the_object = false;
    std::fprintf(stderr,
                 "orthoflow task run: simulated arm: nothing stops its fingers, so a closed hand "
                 "is not checked for the object (the lift check remains)\n");
  }
  return o;
}

}  // namespace

void run_live(const LiveArgs& a) {
  manipulation::TableTaskOptions options = task_options(a);
  std::optional<graphs::TaskCommand> start;
  if (!a.start.empty()) start = start_command(a);
  init_ipc("orthoflow_task");
  auto topics = graphs::graph_topics(a.graph);
  if (!topics) fail(topics.error(), EXIT_USAGE);
  auto objects_in =
      subscriber(topics->objects.str(), {engine::OBJECT_LIST_TYPE_ID, engine::OBJECT_LIST_VERSION},
                 engine::IpcPolicy::LATEST, 1, 0);
  auto categories_in = subscriber(graphs::status_topic(a.graph),
                                  {graphs::STATUS_TYPE_ID, graphs::LEARNING_IPC_VERSION},
                                  engine::IpcPolicy::LATEST, 1, 1);
  auto commands_in = subscriber(graphs::task_commands_topic(a.graph),
                                {graphs::TASK_COMMAND_TYPE_ID, graphs::TASK_IPC_VERSION},
                                engine::IpcPolicy::QUEUE, 16, 0);
  auto status_out = publisher(graphs::task_status_topic(a.graph),
                              {graphs::TASK_STATUS_TYPE_ID, graphs::TASK_IPC_VERSION},
                              sizeof(graphs::TaskStatusPayload), 1);
  auto state_out =
      publisher(engine::ARM_STATE_TOPIC, {engine::ARM_STATE_TYPE_ID, engine::ARM_STATE_VERSION},
                sizeof(engine::ArmStatePayload), 1);
  arm_cli::ArmArgs arm_args = *a.arm;
  arm_args.what = "orthoflow task run";
  arm_args.motion = true;
  arm_args.base_from_camera = options.base_from_camera;
  // A task moves over the table: it never starts without the table's keep-out (docs/SAFETY.md).
  if (arm_cli::load_limits(arm_args).limits.find_keep_out("table") == nullptr)
    fail("the limits have no table keep-out (removed in " + arm_cli::load_limits(arm_args).source +
             "): a task does not start without one",
         EXIT_USAGE);
  auto arm = arm_cli::start_arm(arm_args);
  std::printf("task: commands on %s, status on %s, arm state on %s\n",
              graphs::task_commands_topic(a.graph).c_str(),
              graphs::task_status_topic(a.graph).c_str(), engine::ARM_STATE_TOPIC);
  std::fflush(stdout);

  std::vector<std::string> known;
  std::uint64_t rejected = 0, lists = 0, commands = 0;
  graphs::LiveTaskPorts ports;
  ports.snapshot = [&arm] { return arm->snapshot(); };
  ports.submit = [&arm](const jaco::ArmCommand& c) { return arm->submit(c).has_value(); };
  ports.keep_alive = [&arm] { arm->keep_alive(); };
  ports.publish_state = [&state_out](const engine::ArmStatePayload& p) {
    publish_pod(*state_out, p);
  };
  ports.publish_status = [&](const graphs::TaskStatus& s) {
    graphs::TaskStatusPayload p;
    graphs::encode_task_status(s, p);
    publish_pod(*status_out, p);
    if (s.client == 0 && s.answer != graphs::TaskAnswer::NONE) {  // --start's own answer
      std::cerr << "orthoflow task: " << graphs::to_string(s.answer)
                << (s.message.empty() ? "" : ": " + s.message) << '\n';
    }
  };
  ports.known = [&known] { return known; };
  graphs::LiveTaskSettings settings;
  settings.options = std::move(options);
  graphs::LiveTableTask task(std::move(settings), std::move(ports));

  const std::int64_t begin = now_ns();
  std::int64_t stop_at = 0;    // the time limit: the task is stopped, leave once the arm is still
  std::int64_t halted_at = 0;  // a signal or a stop request halted and latched the arm
  std::string halted_by;
  bool started = false;
  auto list = std::make_unique<engine::ObjectListPayload>();
  int code = EXIT_OK;
  std::string why_exit;
  for (auto next = Clock::now();; next += std::chrono::milliseconds(10)) {
    std::this_thread::sleep_until(next);
    const std::int64_t now = now_ns();
    if (engine::ipc_roudi_lost()) {
      why_exit = "RouDi lost";
      code = EXIT_ROUDI_LOST;
      break;
    }
    rejected += drain(*objects_in, [&](std::span<const std::byte> bytes) {
      if (bytes.size() < sizeof(engine::ObjectListPayload)) return false;
      std::memcpy(static_cast<void*>(list.get()), bytes.data(), sizeof(engine::ObjectListPayload));
      task.on_objects(*list);
      ++lists;
      return true;
    });
    if (auto s = categories_in->take(); s && s->has_value()) {
      if (auto st = graphs::decode_status((*s)->bytes()); st) {
        known.clear();
        for (const graphs::StatusCategory& c : st->categories) known.emplace_back(c.label.view());
      }
    }
    rejected += drain(*commands_in, [&](std::span<const std::byte> bytes) {
      ++commands;
      auto c = graphs::decode_task_command(bytes);
      if (!c)
        task.invalid(c.error(), now);
      else if (stop_at != 0 && c->command.kind == graphs::TaskCommand::Kind::START)
        task.invalid({c->client, c->request, "the task process is shutting down"}, now);
      else
        (void)task.command(*c, now);
      return true;
    });
    // --start: once the graph's objects (and, for serve_a_meal, its categories) have arrived.
    if (start && !started && lists > 0 &&
        (start->task != manipulation::TableTaskKind::SERVE_A_MEAL || !known.empty())) {
      started = true;
      if (task.command({0, 0, *start}, now) != graphs::TaskAnswer::STARTED && a.exit_when_done) {
        code = EXIT_REFUSED;
        why_exit = "the task was refused";
        break;
      }
    }
    // A signal or a stop request halted the arm in place (the guard, the stop listener) and
    // latched it: the task ends where it is, no retreat; the process leaves once the arm is still.
    if (const std::string latched = arm->latch_reason(); !latched.empty() && halted_at == 0) {
      arm->persist_latch();
      halted_at = now;
      halted_by = latched;
      task.halted(latched, now);
    }
    task.tick(now);
    const bool time_up = a.seconds > 0.0 && 1e-9 * double(now - begin) > a.seconds;
    const bool signalled = jaco::signal_stop_requested() != 0;
    if (halted_at != 0 && signalled) {
      const jaco::ArmSnapshot s = arm->snapshot();
      if (!jaco::JacoArm::moving(s) || now - halted_at > 2'000'000'000) {
        why_exit = "halted by " + halted_by +
                   (jaco::JacoArm::moving(s) ? ", the arm still moving "
                                               "2 s later"
                                             : ", the arm at rest") +
                   "; the stop is latched until `orthoflow "
                   "arm reset`";
        if (jaco::JacoArm::moving(s)) code = EXIT_FAILURE_GENERIC;
        break;
      }
      continue;
    }
    if (time_up && stop_at == 0) {
      stop_at = now;
      if (task.running()) {
        graphs::RemoteTaskCommand stop;
        stop.command.kind = graphs::TaskCommand::Kind::STOP;
        (void)task.command(stop, now);
      }
    }
    const jaco::ArmSnapshot s = arm->snapshot();
    const bool still = !task.running() && s.control == jaco::ControlState::IDLE;
    if (stop_at != 0 && (still || now - stop_at > 30'000'000'000)) {
      why_exit = still ? "stopped" : "the arm did not come to rest within 30 s of the stop";
      if (!still) code = EXIT_FAILURE_GENERIC;
      break;
    }
    if (a.exit_when_done && started && still && task.runner() != nullptr &&
        task.runner()->state() == manipulation::TableTaskRunner::State::FINISHED) {
      why_exit = "the task ended";
      break;
    }
  }
  jaco::ArmCommand halt;
  halt.kind = jaco::ArmCommand::Kind::STOP;
  (void)arm->submit(halt);  // whatever happened, nothing moves once this process leaves
  arm.reset();
  nlohmann::json out = {{"exit", why_exit},
                        {"object_lists", lists},
                        {"commands", commands},
                        {"rejected", rejected},
                        {"status", ui::task_status_json(task.status(now_ns()))}};
  if (task.runner() != nullptr) out["report"] = report_json(*task.runner());
  if (a.json) {
    std::cout << out.dump() << '\n';
  } else {
    std::printf("%s: %llu object lists, %llu commands, %llu rejected samples\n", why_exit.c_str(),
                static_cast<unsigned long long>(lists), static_cast<unsigned long long>(commands),
                static_cast<unsigned long long>(rejected));
    if (task.runner() != nullptr) {
      for (const manipulation::MoveRecord& m : task.runner()->moves())
        std::printf("move track %u (%s) to [%.3f, %.3f]: %s\n", m.track, m.label.c_str(), m.to.x(),
                    m.to.y(), m.done ? "done" : m.failure.c_str());
    }
  }
  if (code != EXIT_OK) throw CLI::RuntimeError(code);
}

}  // namespace orthoflow::apps::task_live_cli
