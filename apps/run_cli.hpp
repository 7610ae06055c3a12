#pragma once
/// @file
/// @brief (internal) What the parts of `orthoflow run` share (cmd_run.cpp: the options and the run
/// loop; cmd_run_graph.cpp: the graph and learning settings the options make; cmd_run_summary.cpp:
/// the summary and the outputs written at the end): the options and the error exit.
#include <memory>
#include <optional>
#include <string>

#include "apps/commands.hpp"
#include "engine/arm_state_payload.hpp"
#include "engine/graph.hpp"
#include "engine/telemetry.hpp"
#include "graphs/nodes/labels_writer.hpp"
#include "graphs/services/learning_service.hpp"
#include "graphs/services/line_writer.hpp"
#include "graphs/services/session_log.hpp"
#include "kernels/spin_set.hpp"

namespace orthoflow::apps::run_cli {

/// @brief The options of `orthoflow run` (each field is one option; add_run_command documents
/// them). Plain values; not thread-safe.
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

/// @brief Prints "run: MESSAGE" on stderr and exits with @p code (throws CLI::RuntimeError).
/// @pre none.
[[noreturn]] void fail(const std::string& message, int code);

/// @brief Applies --source and --frames to the graph's source node (apps/graph_overrides.hpp).
/// @pre none (a bad source fails with EXIT_USAGE).
void override_source(engine::GraphSpec& spec, const RunOptions& o);
/// @brief --publish-objects: an ipc_publish node on the objects_output node's objects port, topic
/// orthoflow/<graph>/objects (the graph then needs a running RouDi, like every IPC graph).
/// @pre none (a graph without objects_output fails with EXIT_USAGE).
void add_objects_publisher(engine::GraphSpec& spec);
/// @brief --publish-frames: an ipc_publish node on the objects_output node's out port (each frame
/// as it leaves the graph, with its objects decided), topic orthoflow/<graph>/frames: what
/// `orthoflow bridge dds --frames` reads. RouDi needs a pool of the graph's block size
/// (config/roudi_frames.toml). @pre none (a graph without objects_output fails with EXIT_USAGE).
void add_frames_publisher(engine::GraphSpec& spec);
/// @brief --representation and --dictionary: the describe node's descriptor
/// (docs/SPIN_IMAGES.md). A set of spin images needs more room per object than the graph's blocks
/// have: the pool grows to hold the frames it held before and the sets.
/// @pre none (contradicting options fail with EXIT_USAGE).
void choose_representation(engine::GraphSpec& spec, const RunOptions& o);
/// @brief The learning service's settings: the describe node's descriptor, the learner and its
/// threshold, the --db store. @pre none (a graph without a descriptor fails with EXIT_BAD_INPUT).
[[nodiscard]] graphs::LearningSettings learning_settings(const engine::GraphSpec& spec,
                                                         const RunOptions& o);

/// @brief The run's summary on stdout: frames, objects, recognition and the accuracy against the
/// ground truth. @pre none.
void print_summary(const graphs::SessionSummary& s, const engine::GraphStats& stats,
                   const graphs::LearningService& l);
/// @brief A file the run will write at the end: its directory (and the file, if it exists) must be
/// writable. @pre none (an unwritable path fails with EXIT_FAILURE_GENERIC).
void check_output_path(const std::string& path, const char* flag);
/// @brief --labels-out: what was written; a failed write is an error (exit 1), frames the writer
/// had to drop (every buffer still being written, or an unorganized frame) are reported.
/// @pre the graph has stopped.
void report_labels(graphs::LabelsWriter& labels, const RunOptions& o);
/// @brief After the run: every output the user asked for was written whole, or the exit is
/// non-zero; frames that failed are reported (and fail the run with --on-bad-frame fail).
/// @pre the graph has stopped.
void finish_outputs(const RunOptions& o, graphs::SessionLog& log, const engine::GraphStats& stats,
                    std::unique_ptr<graphs::LineWriter> telemetry);

}  // namespace orthoflow::apps::run_cli
