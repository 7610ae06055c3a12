// `orthoflow evaluate-segmentation --dataset DIR [--graph FILE|tabletop] [--names FILE]
// [--png DIR] [--out DIR] [--json] [--quiet]`: the product's segmentation chain (the tabletop
// graph's by default, as `orthoflow run` runs it) on every labelled frame of DIR (mOSD layout),
// scored per object at pixel IoU >= 0.5 and per plane against the labelled table
// (evaluation/segmentation_eval.hpp, docs/SEGMENTATION.md). Prints the Markdown report (or the
// JSON with --json); --out DIR writes segmentation.json and segmentation.md there. Exits 2 when a
// frame could not be read or scored (its row says why), after reporting the others.
#include <cstdio>
#include <fstream>
#include <iostream>
#include <memory>
#include <string>

#include "apps/commands.hpp"
#include "apps/graph_segmentation.hpp"
#include "core/file_output.hpp"
#include "evaluation/segmentation_eval.hpp"

namespace orthoflow::apps {
namespace {

struct SegEvalArgs {
  std::string dataset;
  std::string graph = "tabletop";
  std::string names;
  std::string png;
  std::string out;
  bool json = false;
  bool quiet = false;
};

[[noreturn]] void fail(const std::string& message, int code) {
  std::cerr << "orthoflow evaluate-segmentation: " << message << '\n';
  throw CLI::RuntimeError(code);
}

void write_text(const std::filesystem::path& path, const std::string& text) {
  if (auto written = core::write_whole_file(path, text); !written)
    fail("cannot write " + written.error(), EXIT_FAILURE_GENERIC);
}

void run_evaluate_segmentation(const SegEvalArgs& a) {
  auto seg = segmentation_of_graph_arg(a.graph);
  if (!seg) fail(seg.error(), EXIT_BAD_INPUT);
  auto frames = evaluation::labelled_frames(a.dataset);
  if (!frames) fail(frames.error().to_string(), EXIT_BAD_INPUT);
  evaluation::SegEvalOptions options;
  if (!a.names.empty()) {
    auto names = evaluation::read_frame_names(a.names);
    if (!names) fail(names.error().to_string(), EXIT_USAGE);
    options.names = std::move(*names);
  }
  options.png_dir = a.png;
  std::unique_ptr<evaluation::Progress> progress;
  if (!a.quiet) {
    progress = std::make_unique<evaluation::Progress>(
        "evaluate-segmentation", frames->size(), stderr, evaluation::Progress::is_terminal(stderr));
    options.progress = progress.get();
  }
  auto report = evaluation::evaluate_segmentation(
      *frames, "orthoflow",
      evaluation::make_chain_segmenter(seg->stages, seg->candidates, &seg->table.verdict), options);
  if (progress) progress->finish();
  if (!report) fail(report.error().to_string(), EXIT_FAILURE_GENERIC);
  const std::vector<evaluation::SegReport> reports{*report};
  const std::string json = evaluation::segmentation_json(reports);
  const std::string md = evaluation::segmentation_markdown(reports);
  std::cout << (a.json ? json : md);
  if (!a.out.empty()) {
    std::error_code ec;
    std::filesystem::create_directories(a.out, ec);
    if (ec) fail("cannot create " + a.out + ": " + ec.message(), EXIT_FAILURE_GENERIC);
    write_text(std::filesystem::path(a.out) / "segmentation.json", json);
    write_text(std::filesystem::path(a.out) / "segmentation.md", md);
  }
  if (report->total.failed > 0) {
    fail(std::to_string(report->total.failed) + " of " + std::to_string(report->total.frames) +
             " frames were not scored (see their rows)",
         EXIT_BAD_INPUT);
  }
}

}  // namespace

void add_evaluate_segmentation_command(CLI::App& app) {
  auto a = std::make_shared<SegEvalArgs>();
  CLI::App* cmd = app.add_subcommand("evaluate-segmentation",
                                     "Score the segmentation chain on labelled frames DIR/*.pcd "
                                     "(mOSD labels; docs/SEGMENTATION.md)");
  cmd->add_option("--dataset", a->dataset, "directory of organized PCD frames with a label field")
      ->required();
  cmd->add_option("--graph", a->graph,
                  "segmentation parameters from this graph file ('tabletop', the default: the "
                  "embedded graph orthoflow run runs)");
  cmd->add_option("--names", a->names,
                  "file of 'frame-stem category' lines: adds a per-category table")
      ->check(CLI::ExistingFile);
  cmd->add_option("--png", a->png, "write DIR/<frame>.png: ground truth left, ours right");
  cmd->add_option("--out", a->out,
                  "write segmentation.json and segmentation.md into this directory");
  cmd->add_flag("--json", a->json, "print the JSON report instead of the Markdown one");
  cmd->add_flag("--quiet", a->quiet, "no progress line");
  cmd->callback([a] { run_evaluate_segmentation(*a); });
}

}  // namespace orthoflow::apps
