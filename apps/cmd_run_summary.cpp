// `orthoflow run`, its end: the summary printed after the run, and the outputs the user asked for
// (labels, JSON lines, telemetry, snapshot), checked before the run and reported after it. The
// options and the run loop are in cmd_run.cpp.
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <iostream>
#include <memory>
#include <string>

#include "apps/run_cli.hpp"
#include "apps/scene_snapshot_png.hpp"

namespace orthoflow::apps::run_cli {

namespace {

std::string percent(const graphs::Score& s) {
  char text[64];
  std::snprintf(text, sizeof text, "%5.1f%% (%llu/%llu)", 100.0 * s.rate(),
                static_cast<unsigned long long>(s.right), static_cast<unsigned long long>(s.asked));
  return text;
}

}  // namespace

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
// that failed are reported (and fail the run with --on-bad-frame fail, or when every frame failed).
void finish_outputs(const RunOptions& o, graphs::SessionLog& log, const engine::GraphStats& stats,
                    std::unique_ptr<graphs::LineWriter> telemetry) {
  int exit_code = EXIT_OK;
  const graphs::SessionSummary summary = log.summary();
  if (!summary.first_error.empty()) {
    std::cerr << "run: " << summary.frames_with_error << " frame(s) failed; the first, frame "
              << summary.first_error_frame << ": " << summary.first_error.to_string() << "\n";
    if (o.on_bad_frame == "fail") exit_code = EXIT_BAD_INPUT;
  }
  // Skipping bad frames is for a run that used some: one that could use none has no result.
  if (summary.frames > 0 && summary.frames_with_error == summary.frames) {
    std::cerr << "run: no frame could be used (" << summary.frames << " of " << summary.frames
              << " failed)\n";
    exit_code = EXIT_BAD_INPUT;
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

}  // namespace orthoflow::apps::run_cli
