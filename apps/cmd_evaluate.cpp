// `orthoflow evaluate --dataset DIR --protocol cv10|teacher|teacher-context|noise|downsample
// [--learner instance,bayes] [--approach nn,1,2]
// [--representation good,spin,bow,lda,local-lda [--spin-keypoints N --spin-width IW
// --spin-support SL --spin-leaf VS] --dictionary FILE
// [--local-topics K] [--local-lda-bayes likelihood|histogram]]
// [--good-mode invariant,reference] [--bins 5,15] [--runs R]
// [--seed S] [--folds K] [--levels MM,...] [--tau T] [--breakpoint N] [--threads N] [--out DIR]
// [--cache DIR | --no-cache]`: the thesis's evaluations (evaluation/, docs/EVALUATION.md). Comma
// lists give every combination as one variant, all evaluated on the same folds, orders and views.
#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <iostream>
#include <memory>
#include <string>
#include <vector>

#include "apps/commands.hpp"
#include "apps/spin_set_options.hpp"
#include "evaluation/progress.hpp"
#include "evaluation/report.hpp"
#include "learning/dictionary.hpp"

namespace orthoflow::apps {
namespace {

struct EvaluateOptions {
  std::string dataset;
  std::string protocol = "cv10";
  std::vector<std::string> learners{"instance"};
  std::vector<std::string> approaches{"nn"};
  std::vector<std::string> modes{"invariant"};
  std::vector<std::size_t> bins{15};
  std::vector<std::string> representations{"good"};
  std::string dictionary;
  std::size_t local_topics = 30;
  kernels::SpinSetParams spin{};  // --spin-*
  std::string local_bayes = "likelihood";
  std::vector<double> levels_mm;
  std::size_t runs = 10;
  std::uint64_t seed = 1;
  std::size_t folds = 10;
  double tau = 0.67;
  std::size_t breakpoint = 100;
  std::size_t threads = 0;
  std::string out;
  std::string cache;
  bool no_cache = false;
  bool quiet = false;
};

[[noreturn]] void fail(const std::string& message, int code) {
  std::cerr << "orthoflow evaluate: " << message << '\n';
  throw CLI::RuntimeError(code);
}

evaluation::Protocol protocol_of(const std::string& p) {
  if (p == "teacher") { return evaluation::Protocol::TEACHER; }
  if (p == "teacher-context") { return evaluation::Protocol::TEACHER_CONTEXT; }
  if (p == "noise") { return evaluation::Protocol::NOISE; }
  if (p == "downsample") { return evaluation::Protocol::DOWNSAMPLE; }
  return evaluation::Protocol::CV10;
}

/// Every combination of the listed learners, rules, representations, modes and bins (rules apply
/// to instance only; modes and bins to GOOD only).
std::vector<evaluation::Variant> variants_of(
    const EvaluateOptions& o, const std::shared_ptr<const kernels::VisualDictionary>& dictionary) {
  std::vector<evaluation::Variant> out;
  for (const std::string& l : o.learners) {
    const bool bayes = l == "bayes";
    const std::vector<std::string> rules = bayes ? std::vector<std::string>{"nn"} : o.approaches;
    for (const std::string& a : rules) {
      evaluation::Variant base;  // the learner and its rule; then each representation
      base.learner = bayes ? evaluation::LearnerKind::BAYES : evaluation::LearnerKind::INSTANCE;
      base.rule = a == "1"   ? evaluation::InstanceRule::APPROACH_1
                  : a == "2" ? evaluation::InstanceRule::APPROACH_2
                             : evaluation::InstanceRule::NEAREST;
      for (const std::string& r : o.representations) {
        if (r == "good" || (bayes && r == "spin")) continue;  // naive Bayes has no form over sets
        evaluation::Variant v = base;
        v.representation = kernels::descriptor_kind(r).value_or(kernels::DescriptorKind::BOW);
        v.dictionary = dictionary;
        v.local_topics.topics = o.local_topics;
        v.topic_histogram_bayes = o.local_bayes == "histogram";
        v.spin_set = o.spin;
        out.push_back(v);
      }
      const bool good = std::find(o.representations.begin(), o.representations.end(), "good") !=
                        o.representations.end();
      for (const std::string& m : good ? o.modes : std::vector<std::string>{}) {
        for (const std::size_t b : o.bins) {
          evaluation::Variant v = base;
          v.mode = m == "reference" ? kernels::GoodMode::REFERENCE : kernels::GoodMode::INVARIANT;
          v.bins = b;
          out.push_back(v);
        }
      }
    }
  }
  return out;
}

std::filesystem::path default_cache() {
  if (const char* xdg = std::getenv("XDG_CACHE_HOME"); xdg != nullptr && *xdg != '\0') {
    return std::filesystem::path(xdg) / "orthoflow/descriptors";
  }
  if (const char* home = std::getenv("HOME"); home != nullptr && *home != '\0') {
    return std::filesystem::path(home) / ".cache/orthoflow/descriptors";
  }
  return {};
}

int exit_code_of(const evaluation::EvalError& e) {
  using Code = evaluation::EvalError::Code;
  switch (e.code) {
    case Code::BAD_CONFIG:
      return EXIT_USAGE;
    case Code::WRITE_FAILED:
      return EXIT_FAILURE_GENERIC;
    default:
      return EXIT_BAD_INPUT;
  }
}

void run_evaluate(const EvaluateOptions& o) {
  auto dataset = evaluation::scan_dataset(o.dataset);
  if (!dataset) { fail(dataset.error().to_string(), EXIT_BAD_INPUT); }
  std::shared_ptr<const kernels::VisualDictionary> dictionary;
  const bool bow = std::any_of(o.representations.begin(), o.representations.end(),
                               [](const std::string& r) { return r != "good" && r != "spin"; });
  if (bow && o.dictionary.empty()) {
    fail(
        "--representation bow, lda or local-lda needs --dictionary FILE (orthoflow dictionary "
        "build)",
        EXIT_USAGE);
  }
  if (bow) {
    auto d = learning::load_dictionary(o.dictionary);
    if (!d) { fail(d.error(), EXIT_BAD_INPUT); }
    dictionary = std::make_shared<const kernels::VisualDictionary>(std::move(d.value()));
  }
  evaluation::EvalOptions eo;
  eo.protocol = protocol_of(o.protocol);
  eo.variants = variants_of(o, dictionary);
  if (eo.variants.empty())
    fail(
        "no variant to evaluate: naive Bayes has no form over spin-image sets (--learner instance)",
        EXIT_USAGE);
  eo.runs = o.runs;
  eo.seed = o.seed;
  eo.folds = o.folds;
  for (const double mm : o.levels_mm) { eo.levels_m.push_back(mm / 1000.0); }
  eo.teacher.tau = o.tau;
  eo.teacher.breakpoint = o.breakpoint;
  eo.threads = o.threads;
  eo.cache_dir = o.no_cache        ? std::filesystem::path{}
                 : o.cache.empty() ? default_cache()
                                   : std::filesystem::path(o.cache);
  std::unique_ptr<evaluation::Progress> progress;
  if (!o.quiet) {
    progress = std::make_unique<evaluation::Progress>(
        "evaluate " + o.protocol, evaluation::evaluation_work(*dataset, eo), stderr,
        evaluation::Progress::is_terminal(stderr));
  }
  auto result = evaluation::evaluate(*dataset, eo, progress.get());
  if (progress) { progress->finish(); }
  if (!result) { fail(result.error().to_string(), exit_code_of(result.error())); }
  for (const std::string& w : result->warnings) {
    std::cerr << "orthoflow evaluate: warning: " << w << '\n';
  }
  std::cout << evaluation::summary_markdown(*result);
  const std::filesystem::path out = o.out.empty()
                                        ? std::filesystem::path("evaluation-" + o.protocol)
                                        : std::filesystem::path(o.out);
  auto written = evaluation::write_report(*result, out);
  if (!written) { fail(written.error().to_string(), EXIT_FAILURE_GENERIC); }
  std::cout << "\n"
            << result->describe.computed << " descriptors computed, " << result->describe.cached
            << " from the cache; " << result->seconds << " s\nwrote";
  for (const auto& f : *written) { std::cout << ' ' << f.string(); }
  std::cout << '\n';
}

}  // namespace

void add_evaluate_command(CLI::App& app) {
  auto o = std::make_shared<EvaluateOptions>();
  CLI::App* cmd = app.add_subcommand(
      "evaluate",
      "Evaluate learners on a dataset DIR/<category>/<instance>/<view>.pcd (docs/EVALUATION.md)");
  cmd->add_option("--dataset", o->dataset, "dataset directory")->required();
  cmd->add_option("--protocol", o->protocol, "cv10, teacher, teacher-context, noise or downsample")
      ->check(CLI::IsMember({"cv10", "teacher", "teacher-context", "noise", "downsample"}));
  cmd->add_option("--learner", o->learners, "instance and/or bayes (comma list)")
      ->delimiter(',')
      ->check(CLI::IsMember({"instance", "bayes"}));
  cmd->add_option("--approach", o->approaches,
                  "instance rule(s): nn (nearest neighbour), 1, 2 (thesis NOCD approaches)")
      ->delimiter(',')
      ->check(CLI::IsMember({"nn", "1", "2"}));
  cmd->add_option("--representation", o->representations,
                  "good, spin, bow, lda and/or local-lda (comma list; spin: the set of a view's "
                  "spin images, instance learner only; bow: a bag of words over --dictionary's "
                  "words; lda: its topics; local-lda: topics learned per category)")
      ->delimiter(',')
      ->check(CLI::IsMember({"good", "spin", "bow", "lda", "local-lda"}));
  add_spin_set_options(cmd, o->spin);
  cmd->add_option("--local-topics", o->local_topics,
                  "local-lda: topics per category (the thesis: 30)")
      ->check(CLI::Range(1, static_cast<int>(kernels::MAX_LOCAL_TOPICS)));
  cmd->add_option("--local-lda-bayes", o->local_bayes,
                  "local-lda with bayes: likelihood (each category's topic model's likelihood of "
                  "the words) or histogram (naive Bayes over the topic histogram)")
      ->check(CLI::IsMember({"likelihood", "histogram"}));
  cmd->add_option("--dictionary", o->dictionary,
                  "bow: the visual words (a file from `orthoflow dictionary build`)");
  cmd->add_option("--good-mode", o->modes, "invariant and/or reference (comma list)")
      ->delimiter(',')
      ->check(CLI::IsMember({"invariant", "reference"}));
  cmd->add_option("--bins", o->bins, "GOOD bins per side (comma list)")
      ->delimiter(',')
      ->check(CLI::Range(1, 256));
  cmd->add_option("--runs", o->runs, "repetitions (category orders / fold splits)")
      ->check(CLI::Range(1, 1000));
  cmd->add_option("--seed", o->seed, "seed of every random choice");
  cmd->add_option("--folds", o->folds, "folds of the cross-validation")->check(CLI::Range(2, 1000));
  cmd->add_option("--levels", o->levels_mm,
                  "noise sigmas or voxel sizes in mm (comma list; default thesis 6.4.3)")
      ->delimiter(',')
      ->check(CLI::Range(0.001, 1000.0));
  cmd->add_option("--tau", o->tau, "teacher: protocol accuracy threshold")
      ->check(CLI::Range(0.0, 0.999));
  cmd->add_option("--breakpoint", o->breakpoint,
                  "teacher: iterations without reaching tau before giving up")
      ->check(CLI::Range(1, 1000000));
  cmd->add_option("--threads", o->threads,
                  "worker threads (0: all cores); results do not depend on it");
  cmd->add_option("--out", o->out, "output directory (default evaluation-<protocol>)");
  cmd->add_option("--cache", o->cache,
                  "descriptor cache directory (default $XDG_CACHE_HOME/orthoflow/descriptors)");
  cmd->add_flag("--no-cache", o->no_cache, "compute every descriptor, read and write no cache");
  cmd->add_flag("--quiet", o->quiet, "no progress bar");
  cmd->callback([o] { run_evaluate(*o); });
  add_derive_views_command(app);
}

}  // namespace orthoflow::apps
