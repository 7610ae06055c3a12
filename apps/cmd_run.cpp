// `orthoflow run`: the tabletop graph end to end on the embedded synthetic session (or a source
// given on the command line), with learning, and a summary of what it saw, learned and how fast.
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <iostream>
#include <memory>
#include <optional>
#include <string>

#include "apps/commands.hpp"
#include "apps/graph_overrides.hpp"
#include "apps/graph_run.hpp"
#include "apps/run_ui.hpp"
#include "apps/scene_snapshot_png.hpp"
#include "apps/spin_set_options.hpp"
#include "engine/engine.hpp"
#include "engine/frame_payload.hpp"
#include "engine/graph.hpp"
#include "engine/ipc_runtime.hpp"
#include "engine/object_list_payload.hpp"
#include "graphs/arm_world_feed.hpp"
#include "graphs/body_filter_node.hpp"
#include "graphs/descriptor_params.hpp"
#include "graphs/embedded_graphs.hpp"
#include "graphs/frame_block.hpp"
#include "graphs/labels_writer.hpp"
#include "graphs/learning_ipc_bridge.hpp"
#include "graphs/learning_payloads.hpp"
#include "graphs/tabletop.hpp"
#include "graphs/world_source.hpp"

namespace orthoflow::apps {

namespace {

std::atomic<bool> g_run_stop{false};
extern "C" void on_run_signal(int /*signal*/) { g_run_stop.store(true, std::memory_order_relaxed); }

struct RunOptions {
  std::string graph;   // empty: the embedded tabletop graph
  std::string source;  // synthetic:SEED | pcd:DIR | kinect[:SERIAL] | kinect-sim[:SEED]
  std::uint64_t frames = 0;
  std::string rate;  // empty: the graph's period (30 Hz for tabletop.yaml)
  std::string db;
  std::string learner = "instance";
  // Plain nearest neighbour with an absolute L2 threshold: in a live session a category starts from
  // a few views of one still object, whose ICD is near zero, which makes NOCD explode for every
  // other instance (docs/TABLETOP.md measures it). NOCD (--approach 1|2) suits memories of many
  // instances.
  std::optional<float> ct;  // default: graphs::default_nn_threshold(the representation)
  std::string approach = "nn";
  std::string json_out;
  std::string labels_out;
  std::string snapshot;
  std::string telemetry_json;
  bool publish_frames = false;   // every frame to orthoflow/<graph>/frames over iceoryx
  bool publish_objects = false;  // every frame's objects to orthoflow/<graph>/objects over iceoryx
  bool ipc_learning =
      false;  // learning commands in, acks and status out over iceoryx (and objects)
  std::string on_bad_frame = "skip";  // skip: count and report; fail: also exit 2
  int threads = 0;
  std::string ui;             // --ui [ADDR:]PORT: the web view beside the graph (empty: off)
  std::string ui_token_file;  // --ui-token-file FILE
  std::string robot_frames;   // --robot-frames FILE: the robot-body filter in front of preprocess
  std::string arm_state_topic = engine::ARM_STATE_TOPIC;
  double arm_state_age_ms = 50.0;
  std::string exclude_zones;   // --exclude-zones: C_instructor capsules, camera frame
  std::string dictionary;      // --dictionary FILE: the describe node's bag of words
  std::string representation;  // good; spin; with --dictionary: bow (its default), lda, local-lda
  kernels::SpinSetParams spin{};  // --spin-*
};

[[noreturn]] void fail(const std::string& message, int code) {
  std::cerr << "run: " << message << "\n";
  throw CLI::RuntimeError(code);
}

// Applies --source and --frames to the graph's source node (apps/graph_overrides.hpp).
void override_source(engine::GraphSpec& spec, const RunOptions& o) {
  if (auto ok = apply_source(spec, o.source, o.frames); !ok) fail(ok.error(), EXIT_USAGE);
}

// --publish-objects: an ipc_publish node on the objects_output node's objects port, topic
// orthoflow/<graph>/objects (the graph then needs a running RouDi, like every IPC graph).
void add_objects_publisher(engine::GraphSpec& spec) {
  const auto output =
      std::find_if(spec.nodes.begin(), spec.nodes.end(),
                   [](const engine::NodeSpec& n) { return n.kind == "objects_output"; });
  if (output == spec.nodes.end())
    fail("--publish-objects needs a graph with an objects_output node", EXIT_USAGE);
  engine::NodeSpec publish;
  publish.name = "publish_objects";
  publish.kind = "ipc_publish";
  const auto topics = graphs::graph_topics(spec.name);
  if (!topics)
    fail("--publish-objects: graph name '" + spec.name + "': " + topics.error(), EXIT_USAGE);
  publish.params.assign("topic", topics->objects.str());
  publish.params.assign("type", "objects");
  publish.params.assign("max_bytes", std::to_string(sizeof(engine::ObjectListPayload)));
  spec.edges.push_back(engine::EdgeSpec{output->name, "objects", publish.name, "in", 0});
  spec.nodes.push_back(std::move(publish));
}

// --publish-frames: an ipc_publish node on the objects_output node's out port (each frame as it
// leaves the graph, with its objects decided), topic orthoflow/<graph>/frames: what `orthoflow
// bridge dds --frames` reads. RouDi needs a pool of the graph's block size
// (config/roudi_frames.toml).
void add_frames_publisher(engine::GraphSpec& spec) {
  const auto output =
      std::find_if(spec.nodes.begin(), spec.nodes.end(),
                   [](const engine::NodeSpec& n) { return n.kind == "objects_output"; });
  if (output == spec.nodes.end())
    fail("--publish-frames needs a graph with an objects_output node", EXIT_USAGE);
  const auto topics = graphs::graph_topics(spec.name);
  if (!topics)
    fail("--publish-frames: graph name '" + spec.name + "': " + topics.error(), EXIT_USAGE);
  engine::NodeSpec publish;
  publish.name = "publish_frames";
  publish.kind = "ipc_publish";
  publish.params.assign("topic", topics->frames.str());
  publish.params.assign("type", "frame");
  // The largest frame the blocks hold (every optional field), not the whole block: the block's
  // results, a set of spin images' 19,600 floats per object among them, never leave the process.
  const std::size_t capacity =
      graphs::FrameBlock::capacity_for(spec.block_bytes, graphs::descriptor_room(&spec));
  publish.params.assign("max_bytes", std::to_string(engine::frame_payload_bytes(
                                         static_cast<std::uint32_t>(capacity), 1,
                                         engine::FRAME_FIELD_RGB | engine::FRAME_FIELD_LABEL)));
  spec.edges.push_back(engine::EdgeSpec{output->name, "out", publish.name, "in", 0});
  spec.nodes.push_back(std::move(publish));
}

// --representation and --dictionary: the describe node's descriptor (docs/SPIN_IMAGES.md). A set
// of spin images needs more room per object than the graph's blocks have: the pool grows to hold
// the frames it held before and the sets.
void choose_representation(engine::GraphSpec& spec, const RunOptions& o) {
  const std::string kind =
      o.representation.empty() ? (o.dictionary.empty() ? "" : "bow") : o.representation;
  if (kind != "spin" && !(o.spin == kernels::SpinSetParams{}))
    fail("--spin-* set the spin images of --representation spin only", EXIT_USAGE);
  if (kind.empty() || kind == "good") {
    if (!o.dictionary.empty()) fail("--dictionary: GOOD has no dictionary", EXIT_USAGE);
    if (kind.empty()) return;  // the graph's own describe node
  }
  const bool words = kind == "bow" || kind == "lda" || kind == "local-lda";
  if (words && o.dictionary.empty())
    fail("--representation " + kind + " needs --dictionary FILE", EXIT_USAGE);
  if (!words && !o.dictionary.empty())
    fail("--representation " + kind + " has no dictionary (drop --dictionary)", EXIT_USAGE);
  bool found = false;
  for (engine::NodeSpec& node : spec.nodes) {
    if (node.kind != "describe") continue;
    engine::ParamMap params;  // the graph's GOOD parameters stay for good; others start afresh
    if (kind == "good") params = node.params;
    params.assign("descriptor", kind);
    if (words) params.assign("dictionary", o.dictionary);
    if (kind == "spin") graphs::assign_spin_set(params, o.spin);
    if (node.params.has("max_object_points"))
      params.assign("max_object_points", *node.params.text("max_object_points", ""));
    node.params = std::move(params);
    found = true;
  }
  if (!found) fail("--representation: the graph has no describe node", EXIT_USAGE);
  graphs::fit_pool_to_descriptors(spec);
}

graphs::LearningSettings learning_settings(const engine::GraphSpec& spec, const RunOptions& o) {
  graphs::LearningSettings settings;
  // The learner reads descriptors of the describe node's specification (and a store must have it
  // too).
  auto descriptor = graphs::descriptor_of_graph(spec);
  if (!descriptor) fail(descriptor.error(), EXIT_BAD_INPUT);
  settings.memory.descriptor = *descriptor;
  settings.memory.learner =
      o.learner == "bayes" ? learning::LearnerKind::BAYES : learning::LearnerKind::INSTANCE;
  settings.memory.instance.classification_threshold =
      o.ct.value_or(o.approach == "nn" ? graphs::default_nn_threshold(*descriptor)
                                       : graphs::DEFAULT_NN_THRESHOLD);
  settings.memory.instance.normalise = o.approach != "nn";
  settings.memory.instance.approach = o.approach == "2" ? learning::NocdApproach::MEAN_DISTANCE
                                                        : learning::NocdApproach::MIN_DISTANCE;
  if (!o.db.empty()) settings.db = o.db;
  return settings;
}

std::string percent(const graphs::Score& s) {
  char text[64];
  std::snprintf(text, sizeof text, "%5.1f%% (%llu/%llu)", 100.0 * s.rate(),
                static_cast<unsigned long long>(s.right), static_cast<unsigned long long>(s.asked));
  return text;
}

void print_summary(const graphs::SessionSummary& s, const engine::GraphStats& stats,
                   const graphs::LearningService& l) {
  if (s.frames == 0 && stats.frames_done.load() > 0) {  // e.g. graphs/example_pipeline.yaml
    std::cout << "frames:      " << stats.frames_done.load() << " processed, "
              << stats.total_drops()
              << " dropped (the graph has no session_log node: no tabletop summary)\n";
    return;
  }
  std::cout << "frames:      " << s.frames << " processed, " << stats.total_drops() << " dropped ("
            << stats.source_drops.load() << " at the source), " << s.frames_with_table
            << " with a table, " << stats.deadline_misses.load() << " over the period, "
            << s.frames_with_error << " with an error\n";
  std::cout << "objects:     " << s.object_views << " object views, " << s.tracks_started
            << " tracks, " << s.key_views << " key views\n";
  std::cout << "recognition: " << s.recognitions << " answers; " << l.teaches() << " lessons";
  if (!s.taught.empty()) {
    std::cout << " (";
    for (std::size_t i = 0; i < s.taught.size(); ++i) std::cout << (i ? ", " : "") << s.taught[i];
    std::cout << ")";
  }
  std::cout << "\n";
  if (s.before_teaching.asked + s.after_teaching.asked > 0) {
    std::cout << "accuracy against the ground truth:\n"
              << "  category not taught yet (Unknown is right): " << percent(s.before_teaching)
              << "\n"
              << "  category taught (its label is right):        " << percent(s.after_teaching)
              << "\n"
              << "    on instances never taught themselves:      " << percent(s.new_instances)
              << "\n";
  }
}

// A file the run will write at the end: its directory (and the file, if it exists) must be
// writable.
void check_output_path(const std::string& path, const char* flag) {
  if (path.empty()) return;
  const std::filesystem::path p(path);
  const std::filesystem::path dir = p.has_parent_path() ? p.parent_path() : ".";
  const bool ok = std::filesystem::exists(p) ? ::access(p.c_str(), W_OK) == 0
                                             : ::access(dir.c_str(), W_OK) == 0;
  if (!ok)
    fail(std::string(flag) + ": cannot write '" + path + "': " + std::strerror(errno),
         EXIT_FAILURE_GENERIC);
}

/// --labels-out: what was written; a failed write is an error (exit 1), frames the writer had to
/// drop (every buffer still being written, or an unorganized frame) are reported.
void report_labels(graphs::LabelsWriter& labels, const RunOptions& o) {
  labels.flush();
  std::cout << "labels: " << labels.written() << " frame(s) written to " << o.labels_out;
  if (labels.dropped() > 0) {
    std::cout << ", " << labels.dropped()
              << " dropped (the writer was busy, or the frame was unorganized)";
  }
  std::cout << "\n";
  if (const std::string e = labels.first_error(); !e.empty()) {
    fail("--labels-out: " + e, EXIT_FAILURE_GENERIC);
  }
}

// After the run: every output the user asked for was written whole, or the exit is non-zero; frames
// that failed are reported (and fail the run with --on-bad-frame fail).
void finish_outputs(const RunOptions& o, graphs::SessionLog& log, const engine::GraphStats& stats,
                    std::unique_ptr<graphs::LineWriter> telemetry) {
  int exit_code = EXIT_OK;
  const graphs::SessionSummary summary = log.summary();
  if (!summary.first_error.empty()) {
    std::cerr << "run: " << summary.frames_with_error << " frame(s) failed; the first, frame "
              << summary.first_error_frame << ": " << summary.first_error.to_string() << "\n";
    if (o.on_bad_frame == "fail") exit_code = EXIT_BAD_INPUT;
  }
  if (log.json() != nullptr && (log.json()->dropped() > 0 || log.json()->failed())) {
    std::cerr << "run: --json-out " << o.json_out << ": " << log.json()->dropped()
              << " lines dropped" << (log.json()->failed() ? ", a write failed" : "") << "\n";
    exit_code = EXIT_FAILURE_GENERIC;
  }
  if (telemetry) {
    telemetry->write(engine::to_json(stats));
    telemetry->flush();
    if (telemetry->failed() || telemetry->dropped() > 0) {
      std::cerr << "run: --telemetry-json " << o.telemetry_json << ": the write failed\n";
      exit_code = EXIT_FAILURE_GENERIC;
    }
  }
  if (!o.snapshot.empty()) {
    if (auto drawn = write_scene_snapshot_png(log.snapshot(), o.snapshot); !drawn) {
      std::cerr << "run: --snapshot: " << drawn.error() << "\n";
      exit_code = EXIT_FAILURE_GENERIC;
    } else {
      std::cout << "snapshot: " << o.snapshot << "\n";
    }
  }
  std::cout.flush();
  if (!std::cout) {
    std::cerr << "run: writing the summary to standard output failed\n";
    exit_code = EXIT_FAILURE_GENERIC;
  }
  if (exit_code != EXIT_OK) throw CLI::RuntimeError(exit_code);
}

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
      "kinect-sim[:SEED] (the simulated camera), replay:DIR, or world:SEED (a simulated "
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
         "(also exit 2 at the end)")
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
