// The orthoflow command-line tool: one binary, one sub-command per job.
#include <cstdio>

#include "apps/commands.hpp"
#include "apps/option_checks.hpp"

int main(int argc, char** argv) {
  CLI::App app{"orthoflow: real-time open-ended 3D object perception"};
  app.require_subcommand(1);
  orthoflow::apps::add_graph_command(app);
  orthoflow::apps::add_describe_command(app);
  orthoflow::apps::add_synth_command(app);
  orthoflow::apps::add_info_command(app);
  orthoflow::apps::add_segment_command(app);
  orthoflow::apps::add_memory_command(app);
  orthoflow::apps::add_ipc_command(app);
  orthoflow::apps::add_run_command(app);
  orthoflow::apps::add_ui_command(app);
  orthoflow::apps::add_remote_commands(app);
  orthoflow::apps::add_evaluate_command(app);
  orthoflow::apps::add_dictionary_command(app);
  orthoflow::apps::add_evaluate_segmentation_command(app);
  orthoflow::apps::add_bench_command(app);
  orthoflow::apps::add_kinect_command(app);
  orthoflow::apps::add_kinect_record_command(*app.get_subcommand("kinect"));
  orthoflow::apps::add_arm_command(app);
  orthoflow::apps::add_calibrate_command(app);
  orthoflow::apps::add_grasp_command(app);
  orthoflow::apps::add_task_command(app);
  orthoflow::apps::add_demo_command(app);
  orthoflow::apps::add_bridge_command(app);
  orthoflow::apps::add_image_command(app);
  orthoflow::apps::check_numeric_options(app);  // every numeric option: finite and non-negative
  app.set_version_flag("--version", ORTHOFLOW_VERSION);
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) { return app.exit(e); }
  return orthoflow::apps::EXIT_OK;
}
