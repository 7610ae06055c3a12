#pragma once
/// @file
/// @brief Sub-commands of the `orthoflow` CLI. Each `add_*_command` registers one sub-command (with
/// `--help`) on the top-level app. A command prints its result to stdout, its errors to stderr, and
/// reports failure by throwing `CLI::RuntimeError(exit_code)` from its callback (exit codes below).
#include <CLI/CLI.hpp>

namespace orthoflow::apps {

/// Exit codes shared by every sub-command.
inline constexpr int EXIT_OK = 0;
inline constexpr int EXIT_FAILURE_GENERIC = 1;  ///< the operation failed (message on stderr)
inline constexpr int EXIT_BAD_INPUT = 2;        ///< unreadable or malformed input file
inline constexpr int EXIT_USAGE =
    106;  ///< bad arguments (the code CLI11 uses for RequiredError; its own validators exit 105)
/// IPC exit codes (docs/IPC.md), used by `ipc ...` and by every command that runs IPC nodes.
inline constexpr int EXIT_NO_ROUDI = 20;    ///< RouDi unreachable
inline constexpr int EXIT_POOLS = 21;       ///< RouDi's pools do not fit the topics
inline constexpr int EXIT_ROUDI_LOST = 22;  ///< RouDi disappeared while running
/// Remote-client exit codes (`teach|correct|ask|forget|undo|state --url`).
inline constexpr int EXIT_REFUSED = 30;      ///< the robot answered and refused (HTTP 4xx/5xx)
inline constexpr int EXIT_UNREACHABLE = 31;  ///< no answer: cannot connect, or timed out

/// @brief `graph check|dot|run FILE`: validate, draw (Graphviz) and run dataflow graph files.
void add_graph_command(CLI::App& app);
/// @brief `describe FILE.pcd`: GOOD descriptor, object frame, bbox, projection order; --json,
/// --png.
void add_describe_command(CLI::App& app);
/// @brief `synth` and `synth-dataset`: synthetic Kinect tabletop frames and the object-view
/// dataset.
void add_synth_command(CLI::App& app);
/// @brief `info FILE [--json]`: fields, point count, layout, finite points, bounding box of a
/// .pcd/.ply file.
void add_info_command(CLI::App& app);
/// @brief `segment FILE.pcd`: tabletop plane, objects and per-stage timings; --json, --repeat,
/// PCL-named parameters.
void add_segment_command(CLI::App& app);
/// @brief `memory --db DIR teach|ask|correct|list|stats|forget|export|import|calibrate`: the
/// perceptual memory.
void add_memory_command(CLI::App& app);

/// @brief `ipc config|doctor|echo|send|run`: operate the iceoryx transport (exit codes 20-22 in
/// docs/IPC.md).
void add_ipc_command(CLI::App& app);

/// @brief `teach|correct TRACK LABEL`, `ask TRACK`, `forget LABEL`, `undo`, `state`, each with
/// `--url http://HOST:PORT`: a thin client of a running orthoflow's teaching API (exit 30 refused,
/// 31 unreachable).
void add_remote_commands(CLI::App& app);

/// @brief `calibrate hand-eye|simulate-samples|find-target|simulate-frames`: the camera's pose in
/// the arm's base frame (apps/cmd_calibrate.cpp).
void add_calibrate_command(CLI::App& app);
/// @brief `grasp --robot-frames F --objects RUN.jsonl`: grasp plans of a run's objects
/// (apps/cmd_grasp.cpp).
void add_grasp_command(CLI::App& app);
void add_demo_command(CLI::App& app);
/// @brief `orthoflow task plan clear_table|serve_a_meal`: the table tasks planned on a run's
/// objects; `task run|start|stop|status` (apps/cmd_task_live.cpp): run them on the arm.
void add_task_command(CLI::App& app);
/// @brief `run`, `start`, `stop`, `status` under @p task (apps/cmd_task_live.cpp).
void add_live_task_commands(CLI::App* task);

/// @brief `run`: the tabletop graph on the embedded session or a given source; summary, JSON lines,
/// snapshot.
void add_run_command(CLI::App& app);
/// @brief `orthoflow bridge dds`: a graph's objects, frames and learning commands on DDS with
/// ROS 2's names (apps/cmd_bridge.cpp, docs/DDS.md).
void add_bridge_command(CLI::App& app);
/// @brief `orthoflow image check|render`: a robot image's configuration (apps/cmd_image.cpp,
/// docs/DEPLOY.md).
void add_image_command(CLI::App& app);
/// @brief `orthoflow ui`: the web view over a graph in another process (apps/run_ui.cpp).
void add_ui_command(CLI::App& app);
/// @brief `evaluate --dataset DIR --protocol ...`: cross-validation, simulated teacher, context
/// change, robustness.
void add_evaluate_command(CLI::App& app);
/// @brief `orthoflow dictionary build|show`: the bag of words' visual words (cmd_dictionary.cpp).
void add_dictionary_command(CLI::App& app);
/// @brief `derive-views FILE... --out DIR`: partial views of single object views, as a dataset
/// (registered by add_evaluate_command).
void add_derive_views_command(CLI::App& app);
/// @brief `evaluate-segmentation --dataset DIR`: the chain scored on labelled frames (mOSD labels).
void add_evaluate_segmentation_command(CLI::App& app);
/// @brief `bench latency`: frame-to-labels latency of a graph on the user's machine, with stress.
void add_bench_command(CLI::App& app);
/// @brief `kinect list|info|stream [--sim]`: the Kinect v1 camera through orthoflow's driver.
void add_kinect_command(CLI::App& app);
/// @brief `kinect record DIR`: the camera in libfreenect's fakenect format (on the kinect command).
void add_kinect_record_command(CLI::App& kinect_command);
/// @brief `arm list|info|state|home|retract|move|fingers|stop [--sim]`: the Kinova JACO through
/// orthoflow's driver.
void add_arm_command(CLI::App& app);
}  // namespace orthoflow::apps
