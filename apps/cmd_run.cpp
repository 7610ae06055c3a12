// `orthoflow run`: the tabletop graph end to end on the embedded synthetic session (or a source
// given on the command line), with learning, and a summary of what it saw, learned and how fast.
// This file holds the options and the run loop; the graph and learning settings the options make
// are in cmd_run_graph.cpp, the summary and the outputs in cmd_run_summary.cpp (apps/run_cli.hpp).
#include <unistd.h>

#include <atomic>
#include <csignal>
#include <cstdlib>
#include <iostream>
#include <memory>
#include <string>

#include "apps/commands.hpp"
#include "apps/graph_overrides.hpp"
#include "apps/graph_run.hpp"
#include "apps/run_cli.hpp"
#include "apps/run_ui.hpp"
#include "apps/spin_set_options.hpp"
#include "engine/engine.hpp"
#include "engine/graph.hpp"
#include "engine/ipc_runtime.hpp"
#include "graphs/channels/learning_payloads.hpp"
#include "graphs/embedded_graphs.hpp"
#include "graphs/nodes/body_filter_node.hpp"
#include "graphs/nodes/labels_writer.hpp"
#include "graphs/nodes/world_source.hpp"
#include "graphs/services/learning_ipc_bridge.hpp"
#include "graphs/sessions/arm_world_feed.hpp"
#include "graphs/tabletop.hpp"

namespace orthoflow::apps {

namespace run_cli {

[[noreturn]] void fail(const std::string& message, int code) {
  std::cerr << "run: " << message << "\n";
  throw CLI::RuntimeError(code);
}

}  // namespace run_cli

namespace {

using namespace run_cli;

std::atomic<bool> g_run_stop{false};
extern "C" void on_run_signal(int /*signal*/) { g_run_stop.store(true, std::memory_order_relaxed); }

// --source world:SEED: the world of that seed, following the arm states on --arm-state-topic.
std::unique_ptr<graphs::ArmWorldFeed> open_world(const RunOptions& o) {
  const std::string digits = o.source.substr(6);
  if (digits.empty() || digits.size() > 19 ||
      digits.find_first_not_of("0123456789") != std::string::npos)
    fail("--source world:SEED needs a decimal seed, not '" + digits + "'", EXIT_USAGE);
  if (auto init = engine::init_ipc_runtime("orthoflow_" + std::to_string(::getpid())); !init)
    fail("--source world: " + engine::to_string(init.error()), EXIT_NO_ROUDI);
  auto world = graphs::ArmWorldFeed::create(std::stoull(digits), o.arm_state_topic, o.frames);
  if (!world) fail(world.error(), EXIT_FAILURE_GENERIC);
  return std::move(*world);
}

void run(const RunOptions& o) {
  auto spec = o.graph.empty() ? engine::parse_graph(std::string(graphs::embedded_tabletop_yaml()),
                                                    "embedded:tabletop.yaml")
                              : engine::load_graph_file(o.graph);
  if (!spec) fail(engine::to_string(spec.error()), EXIT_BAD_INPUT);
  override_source(*spec, o);
  apply_rate(*spec, o.rate);
  choose_representation(*spec, o);
  if (!o.robot_frames.empty() || !o.exclude_zones.empty()) {
    engine::ParamMap body;
    if (o.robot_frames.empty()) {
      body.assign("arm", "none");
    } else {
      body.assign("robot_frames", o.robot_frames);
      body.assign("state_topic", o.arm_state_topic);
      body.assign("max_state_age_ms", std::to_string(o.arm_state_age_ms));
    }
    if (!o.exclude_zones.empty()) body.assign("exclude", o.exclude_zones);
    if (auto ok = graphs::insert_body_filter(*spec, body); !ok) fail(ok.error(), EXIT_USAGE);
  }
  if (o.publish_objects || o.ipc_learning) add_objects_publisher(*spec);
  if (o.publish_frames) add_frames_publisher(*spec);
  auto learning = graphs::LearningService::open(learning_settings(*spec, o));
  if (!learning) fail(learning.error(), EXIT_FAILURE_GENERIC);
  for (const std::string& warning : (*learning)->open_warnings()) {
    std::cerr << "run: warning: --db " << o.db << ": " << warning << '\n';
  }
  // Every output the user asked for is checked before the run, so a bad path fails at once.
  check_output_path(o.snapshot, "--snapshot");
  std::unique_ptr<graphs::LineWriter> telemetry;
  if (!o.telemetry_json.empty()) {
    auto writer = graphs::LineWriter::open(o.telemetry_json);
    if (!writer) fail(writer.error(), EXIT_FAILURE_GENERIC);
    telemetry = std::move(*writer);
  }
  std::unique_ptr<graphs::LineWriter> json;
  if (!o.json_out.empty()) {
    auto writer = graphs::LineWriter::open(o.json_out);
    if (!writer) fail(writer.error(), EXIT_FAILURE_GENERIC);
    json = std::move(*writer);
  }
  graphs::SessionLog log(std::move(json));
  std::unique_ptr<graphs::LabelsWriter> labels;
  if (!o.labels_out.empty()) {
    auto writer = graphs::LabelsWriter::open(o.labels_out,
                                             graphs::FrameBlock::capacity_for(spec->block_bytes));
    if (!writer) fail(writer.error(), EXIT_FAILURE_GENERIC);
    labels = std::move(*writer);
  }
  // The web view reads every frame's objects through the hub (only when --ui asks for it).
  graphs::ObjectsHub objects;
  auto registry = graphs::make_tabletop_registry(**learning, log, o.ui.empty() ? nullptr : &objects,
                                                 labels.get());
  // --source world:SEED: the simulated table and camera, reacting to the arm's streamed states.
  std::unique_ptr<graphs::ArmWorldFeed> world;
  if (o.source.rfind("world:", 0) == 0) world = open_world(o);
  graphs::add_world_source_node(registry, world.get());
  auto graph = engine::build_graph(*spec, registry);
  if (!graph) fail(engine::to_string(graph.error()), EXIT_BAD_INPUT);
  g_run_stop.store(false);
  auto previous_int = std::signal(SIGINT, on_run_signal);
  auto previous_term = std::signal(SIGTERM, on_run_signal);
  engine::Engine engine(**graph, {o.threads});
  std::unique_ptr<RunUi> ui;
  if (!o.ui.empty()) {
    ui = start_run_ui(o.ui, o.ui_token_file, **learning, objects, engine.stats(), spec->period_ns,
                      spec->name);
  }
  // --ipc-learning: the graph's objects publisher registered this process with RouDi.
  std::unique_ptr<graphs::LearningIpcBridge> bridge;
  if (o.ipc_learning) {
    auto opened = graphs::LearningIpcBridge::open(spec->name, **learning, engine.stats());
    if (!opened) fail("--ipc-learning: " + opened.error(), EXIT_FAILURE_GENERIC);
    bridge = std::move(*opened);
    std::cout << "run: learning commands on " << graphs::learning_commands_topic(spec->name)
              << ", answers on " << graphs::learning_acks_topic(spec->name) << "\n";
    std::cout.flush();
  }
  // --publish-objects: a lost RouDi ends the run within ~100 ms (docs/IPC.md), exit 22 below.
  const auto reason = run_watching_roudi(engine, {o.frames, &g_run_stop});
  std::signal(SIGINT, previous_int);
  std::signal(SIGTERM, previous_term);
  ui.reset();  // the server and its learning client go before the graph's results are read
  if (bridge) {
    const graphs::LearningIpcCounters& c = bridge->counters();
    std::cout << "ipc learning: " << c.commands.load() << " commands (" << c.invalid.load()
              << " invalid, " << c.timeouts.load() << " unanswered), " << c.acks.load()
              << " answers, " << c.statuses.load() << " statuses published\n";
    bridge.reset();
  }
  (*learning)->flush();
  if (log.json() != nullptr) log.json()->flush();
  if (labels) report_labels(*labels, o);
  std::cout << "orthoflow run: graph '" << (*graph)->spec.name << "'"
            << (reason == engine::StopReason::STOP_REQUESTED ? " (stopped by signal)" : "") << "\n";
  print_summary(log.summary(), engine.stats(), **learning);
  if (world) {
    const graphs::WorldTally t = world->tally();
    std::cout << "world: " << t.objects << " objects, " << t.moved << " moved, " << t.fallen
              << " fell, " << t.arm_states << " arm states applied over " << t.frames
              << " frames\n";
  }
  std::cout << engine::format_table(engine.stats());
  const bool roudi_lost = engine::ipc_roudi_lost();
  if (roudi_lost) {
    std::cerr << "run: " << roudi_lost_text("publishing objects") << "; the run stopped\n";
  }
  finish_outputs(o, log, engine.stats(), std::move(telemetry));
  if (roudi_lost) throw CLI::RuntimeError(EXIT_ROUDI_LOST);
}

}  // namespace

void add_run_command(CLI::App& app) {
  auto o = std::make_shared<RunOptions>();
  auto* cmd = app.add_subcommand(
      "run", "Run the tabletop graph (default: the embedded synthetic session) and summarise");
  cmd->add_option("--graph", o->graph, "graph file (default: the embedded graphs/tabletop.yaml)");
  cmd->add_option(
      "--source", o->source,
      "synthetic:SEED, pcd:DIR, kinect[:SERIAL] (the camera over USB), "
      "kinect-sim[:SEED] (the simulated camera), replay:DIR (a fakenect recording), tum:DIR (a TUM "
      "RGB-D benchmark folder), or world:SEED (a simulated "
      "table seen by the simulated camera, reacting to the arm states on "
      "--arm-state-topic; needs RouDi) (default: the graph's source)");
  cmd->add_option("--frames", o->frames, "stop after N frames (synthetic: session length)");
  cmd->add_option(
      "--robot-frames", o->robot_frames,
      "robot frames file (base_from_camera): removes the arm from every frame before "
      "segmentation, from its joint states on --arm-state-topic (docs/MANIPULATION.md)");
  cmd->add_option("--arm-state-topic", o->arm_state_topic,
                  "iceoryx topic of the arm's joint states (default orthoflow/jaco/state, what "
                  "`orthoflow arm state --follow --publish` sends)");
  cmd->add_option("--arm-state-age-ms", o->arm_state_age_ms,
                  "a frame whose arm state is further than this from its time is dropped (default "
                  "50)")
      ->check(CLI::Range(1.0, 1000.0));
  cmd->add_option(
      "--exclude-zones", o->exclude_zones,
      "instructor zones (C_instructor): 'ax,ay,az,bx,by,bz,r;...' capsules in the camera "
      "frame (m) whose points are removed before segmentation, so a person's hand there "
      "is never taught");
  cmd->add_option("--rate", o->rate,
                  "source rate in Hz, or max (no pacing, no deadline); default: the graph's period")
      ->check(check_rate);
  cmd->add_option("--dictionary", o->dictionary,
                  "describe objects by the bag of words over this dictionary "
                  "(`orthoflow dictionary build`) instead of GOOD; a --db store must have it");
  cmd->add_option("--representation", o->representation,
                  "the describe node's descriptor: good, spin (the set of a view's spin images, "
                  "instance learner; --spin-*), or with --dictionary: bow (the bag of words, the "
                  "default with --dictionary), lda (its topics; a dictionary built with --topics) "
                  "or local-lda (word counts; topics learned per category)")
      ->check(CLI::IsMember({"good", "spin", "bow", "lda", "local-lda"}));
  add_spin_set_options(cmd, o->spin);
  cmd->add_option("--db", o->db,
                  "perceptual memory directory (LevelDB); default: learn in memory only");
  cmd->add_option("--learner", o->learner, "instance or bayes")
      ->check(CLI::IsMember({"instance", "bayes"}));
  cmd->add_option(
         "--ct", o->ct,
         "classification threshold (nn: the L2 distance, default 0.3, or with spin the set "
         "distance, default 0.15; 1|2: NOCD, default 0.3; docs/TABLETOP.md)")
      ->check(CLI::PositiveNumber);
  cmd->add_option("--approach", o->approach,
                  "instance learner: 1 (NOCD, min), 2 (NOCD, mean) or nn (plain nearest neighbour, "
                  "CT on L2)")
      ->check(CLI::IsMember({"1", "2", "nn"}));
  cmd->add_option("--json-out", o->json_out, "one JSON line per frame to FILE ('-' = stdout)");
  cmd->add_option("--labels-out", o->labels_out,
                  "write DIR/frame_<id>.pcd per frame: the organized cloud with a label field (0 "
                  "none, 1 table, k >= 2 object k - 2 of the frame's objects), off the frame path");
  cmd->add_option("--snapshot", o->snapshot,
                  "PNG of the last frame with objects, seen from above the table");
  cmd->add_option("--telemetry-json", o->telemetry_json, "engine telemetry as JSON to FILE");
  cmd->add_option(
         "--on-bad-frame", o->on_bad_frame,
         "a frame that fails (unreadable file, no table, ...): skip (count and report) or fail "
         "(also exit 2 at the end); a run in which every frame failed exits 2 either way")
      ->check(CLI::IsMember({"skip", "fail"}));
  cmd->add_flag(
      "--publish-objects", o->publish_objects,
      "publish every frame's objects on the iceoryx topic orthoflow/<graph>/objects (needs RouDi)");
  cmd->add_flag("--publish-frames", o->publish_frames,
                "publish every frame on the iceoryx topic orthoflow/<graph>/frames (RouDi needs a "
                "pool of the graph's block size: config/roudi_frames.toml)");
  cmd->add_flag("--ipc-learning", o->ipc_learning,
                "also take learning commands from other processes over iceoryx (orthoflow ui; "
                "orthoflow/<graph>/learning_commands, answers on .../learning_acks, memory and "
                "telemetry on .../status; implies --publish-objects; docs/IPC.md)");
  cmd->add_option("--threads", o->threads, "arena threads (0 = all cores)")
      ->check(CLI::Range(0, 1024));
  auto* ui = cmd->add_option("--ui", o->ui,
                             "serve the live web view and its JSON API on [ADDR:]PORT while the "
                             "graph runs (default address 127.0.0.1; another address needs the "
                             "bearer token printed at start; ui/README.md)")
                 ->check(check_ui_listen);
  cmd->add_option("--ui-token-file", o->ui_token_file,
                  "read the web view's bearer token from FILE instead of generating one")
      ->needs(ui);
  cmd->callback([o] { run(*o); });
}

}  // namespace orthoflow::apps
