// The orthoflow command-line tool: one binary, one sub-command per job.
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <iostream>

#include "apps/commands.hpp"
#include "apps/option_checks.hpp"

namespace {

/// Every command's printed answer reaches standard output or the exit says it did not: a full disk,
/// /dev/full or a closed pipe behind stdout turns an exit 0 into 1 with a message on stderr.
int with_stdout_checked(int code) {
  std::cout.flush();
  errno = 0;
  const bool flushed = std::fflush(stdout) == 0;
  if (flushed && std::ferror(stdout) == 0 && !std::cout.bad()) return code;
  std::fprintf(stderr, "orthoflow: writing to standard output failed%s%s\n", errno != 0 ? ": " : "",
               errno != 0 ? std::strerror(errno) : "");
  return code == orthoflow::apps::EXIT_OK ? orthoflow::apps::EXIT_FAILURE_GENERIC : code;
}

}  // namespace

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
  } catch (const CLI::ParseError& e) { return with_stdout_checked(app.exit(e)); }
  return with_stdout_checked(orthoflow::apps::EXIT_OK);
}
