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
// graphs/live_table_task.hpp runs the task; docs/MANIPULATION.md section 5 tells the whole story.
#include <atomic>
#include <chrono>
#include <csignal>
#include <cstdio>
#include <cstring>
#include <iostream>
#include <optional>
#include <random>
#include <string>
#include <thread>
#include <vector>

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include "apps/arm_cli.hpp"
#include "apps/commands.hpp"
#include "apps/perceived_scene.hpp"
#include "engine/arm_state_payload.hpp"
#include "engine/ipc_pubsub.hpp"
#include "engine/ipc_runtime.hpp"
#include "graphs/learning_ipc_bridge.hpp"
#include "graphs/learning_payloads.hpp"
#include "graphs/live_table_task.hpp"
#include "graphs/table_task_session.hpp"
#include "graphs/task_payloads.hpp"
#include "manipulation/robot_frames.hpp"
#include "ui/ui_json.hpp"

namespace orthoflow::apps {
namespace {

namespace jaco = drivers::jaco;
using Clock = std::chrono::steady_clock;

std::atomic<bool> g_stop{false};
extern "C" void on_task_stop_signal(int /*signal*/) { g_stop.store(true); }

std::int64_t now_ns() { return Clock::now().time_since_epoch().count(); }

[[noreturn]] void fail(const std::string& what, int code = EXIT_FAILURE_GENERIC) {
  std::cerr << "orthoflow task: " << what << '\n';
  throw CLI::RuntimeError(code);
}

struct LiveArgs {
  std::shared_ptr<arm_cli::ArmArgs> arm = std::make_shared<arm_cli::ArmArgs>();
  std::string graph = "tabletop";
  std::string frames;
  std::string start;               // run --start TASK; start TASK
  std::vector<std::string> bring;  // serve_a_meal's categories
  std::vector<double> area{0.20, -0.50, 0.56, -0.15};
  std::vector<std::string> keep{"plate"};
  std::vector<double> user_place{-0.35, -0.50};
  double seconds = 0.0;              // run: 0 = until a signal
  double timeout_s = 5.0;            // start / stop / status: wait this long for the answer
  double perception_age_ms = 300.0;  // the stale-perception interlock
  bool exit_when_done = false;
  bool json = false;
};

engine::IpcTopic topic_of(const std::string& name) {
  auto t = engine::parse_topic(name);
  if (!t) fail("bad topic " + name + ": " + engine::to_string(t.error()), EXIT_USAGE);
  return *t;
}

void init_ipc(const std::string& who) {
  if (auto init = engine::init_ipc_runtime(who + "_" + std::to_string(::getpid())); !init)
    fail(to_string(init.error()), EXIT_NO_ROUDI);
}

std::unique_ptr<engine::IpcPublisher> publisher(const std::string& topic,
                                                engine::IpcPayloadType type, std::size_t bytes,
                                                std::uint64_t history) {
  auto pools = engine::query_roudi_pools(std::chrono::milliseconds(3000));
  if (!pools) fail(to_string(pools.error()), EXIT_NO_ROUDI);
  auto p = engine::IpcPublisher::create(topic_of(topic), {type, bytes, history, false}, *pools);
  if (!p)
    fail(to_string(p.error()), p.error().code == engine::IpcError::Code::NO_FITTING_POOL
                                   ? EXIT_POOLS
                                   : EXIT_FAILURE_GENERIC);
  return std::move(*p);
}

std::unique_ptr<engine::IpcSubscriber> subscriber(const std::string& topic,
                                                  engine::IpcPayloadType type,
                                                  engine::IpcPolicy policy, std::uint64_t depth,
                                                  std::uint64_t history) {
  auto s = engine::IpcSubscriber::create(topic_of(topic), {type, policy, depth, history});
  if (!s) fail(to_string(s.error()));
  return std::move(*s);
}

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

template <class Payload>
void publish_pod(engine::IpcPublisher& out, const Payload& p) {
  (void)out.publish_copy({reinterpret_cast<const std::byte*>(&p), sizeof p});
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
  return o;
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
  auto arm = arm_cli::start_arm(*a.arm);
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

  g_stop.store(false);
  const auto previous_int = std::signal(SIGINT, on_task_stop_signal);
  const auto previous_term = std::signal(SIGTERM, on_task_stop_signal);
  const std::int64_t begin = now_ns();
  std::int64_t stop_at = 0;  // a stop was asked (signal, time limit): leave once the arm is still
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
    task.tick(now);
    const bool time_up = a.seconds > 0.0 && 1e-9 * double(now - begin) > a.seconds;
    if ((g_stop.load() || time_up) && stop_at == 0) {
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
  std::signal(SIGINT, previous_int);
  std::signal(SIGTERM, previous_term);
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

// One command to a running `task run`, and its answer.
void send_command(const LiveArgs& a, const std::optional<graphs::TaskCommand>& command) {
  init_ipc("orthoflow_task_cli");
  auto status_in = subscriber(graphs::task_status_topic(a.graph),
                              {graphs::TASK_STATUS_TYPE_ID, graphs::TASK_IPC_VERSION},
                              engine::IpcPolicy::QUEUE, 64, 1);
  std::unique_ptr<engine::IpcPublisher> out;
  std::uint64_t client = 0;
  const std::uint64_t request = 1;
  if (command) {
    out = publisher(graphs::task_commands_topic(a.graph),
                    {graphs::TASK_COMMAND_TYPE_ID, graphs::TASK_IPC_VERSION},
                    sizeof(graphs::TaskCommandPayload), 0);
    std::random_device device;
    client = ((static_cast<std::uint64_t>(device()) << 32U) ^ device()) | 1U;
  }
  const auto deadline = Clock::now() + std::chrono::duration<double>(a.timeout_s);
  // Wait for the task process to subscribe (it may have just started), then send once.
  bool sent = !command;
  while (!sent && Clock::now() < deadline) {
    if (out->has_subscribers()) {
      graphs::TaskCommandPayload p;
      if (!graphs::encode_task_command(*command, client, request, p))
        fail("a category is not a valid label", EXIT_USAGE);
      publish_pod(*out, p);
      sent = true;
      break;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  if (!sent) fail("no `orthoflow task run` for graph " + a.graph + " answered", EXIT_UNREACHABLE);
  while (Clock::now() < deadline) {
    auto s = status_in->take();
    if (s && s->has_value()) {
      auto st = graphs::decode_task_status((*s)->bytes());
      if (st && (!command || (st->client == client && st->request == request))) {
        const nlohmann::json j = ui::task_status_json(*st);
        if (a.json)
          std::cout << j.dump() << '\n';
        else
          std::printf("%s: %s%s%s (move %u of %u, %u done)\n", graphs::to_string(st->answer),
                      graphs::to_string(st->state), st->message.empty() ? "" : ": ",
                      st->message.c_str(), st->move, st->moves, st->done);
        if (command && (st->answer == graphs::TaskAnswer::REFUSED ||
                        st->answer == graphs::TaskAnswer::INVALID))
          throw CLI::RuntimeError(EXIT_REFUSED);
        return;
      }
      continue;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  fail("no answer from `orthoflow task run` within " + std::to_string(a.timeout_s) + " s",
       EXIT_UNREACHABLE);
}

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
