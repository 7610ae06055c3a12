// `orthoflow memory --db DIR [--learner instance|bayes] [--bins N] [--mode M] [--ct X] <action>`:
// the perceptual memory (learning/perceptual_memory.hpp, docs/LEARNING.md) from the command line.
// Actions: teach LABEL FILE.pcd..., ask FILE.pcd [--json], correct LABEL FILE.pcd, list, stats,
// forget LABEL, export FILE, import FILE, calibrate. Descriptors are the store's specification
// (kernels::Describer; GOOD, or over a dictionary with --representation bow|lda|local-lda /
// --dictionary FILE) of each PCD.
#include <cmath>
#include <iostream>
#include <memory>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "apps/commands.hpp"
#include "apps/option_checks.hpp"
#include "apps/spin_set_options.hpp"
#include "formats/pcd_io.hpp"
#include "kernels/descriptor_spec.hpp"
#include "learning/calibration.hpp"
#include "learning/dictionary.hpp"
#include "learning/perceptual_memory.hpp"

namespace orthoflow::apps {
namespace {

struct MemoryOptions {
  std::string db;
  std::string learner = "instance";
  std::size_t bins = 15;
  std::string mode = "invariant";
  std::optional<float> ct;
  std::string representation = "good";
  std::string dictionary;
  kernels::SpinSetParams spin{};  // --spin-*
  std::string label;
  std::vector<std::string> files;
  std::string file;
  bool json = false;
};

[[noreturn]] void fail(const std::string& message, int code) {
  std::cerr << "orthoflow memory: " << message << '\n';
  throw CLI::RuntimeError(code);
}

learning::MemoryConfig config_of(const MemoryOptions& o) {
  learning::MemoryConfig cfg;
  cfg.descriptor = kernels::DescriptorSpec::make_good(
      o.bins, o.mode == "reference" ? kernels::GoodMode::REFERENCE : kernels::GoodMode::INVARIANT);
  // A bag-of-words store: with --dictionary, those words (a new store takes them; an existing one
  // must have them); without, the store's own.
  if (o.representation == "spin") {  // sets of spin images: the instance learner, no dictionary
    const kernels::GoodConfig good = cfg.descriptor.good;
    cfg.descriptor = kernels::DescriptorSpec::make_spin_set(o.spin);
    cfg.descriptor.good = good;
  } else if (o.representation != "good" || !o.dictionary.empty()) {
    std::shared_ptr<const kernels::VisualDictionary> words;
    if (!o.dictionary.empty()) {
      auto d = learning::load_dictionary(o.dictionary);
      if (!d) { fail(d.error(), EXIT_BAD_INPUT); }
      words = std::make_shared<const kernels::VisualDictionary>(std::move(d.value()));
    }
    const kernels::GoodConfig good = cfg.descriptor.good;
    const auto kind =
        kernels::descriptor_kind(o.representation).value_or(kernels::DescriptorKind::BOW);
    cfg.descriptor = kernels::DescriptorSpec::over_dictionary(
        kind == kernels::DescriptorKind::GOOD ? kernels::DescriptorKind::BOW : kind,
        std::move(words));
    cfg.descriptor.good = good;
  }
  cfg.learner =
      o.learner == "bayes" ? learning::LearnerKind::BAYES : learning::LearnerKind::INSTANCE;
  if (o.ct) { cfg.instance.classification_threshold = *o.ct; }
  return cfg;
}

// Only commands that write may create a store (teach, correct, import); the read-only ones (ask,
// list, stats, export, calibrate) never change it and work on a read-only store.
learning::PerceptualMemory open_memory(const MemoryOptions& o, learning::OpenMode mode) {
  auto memory_result = learning::PerceptualMemory::open(o.db, config_of(o), mode);
  if (!memory_result) {
    const bool bad_input =
        memory_result.error().code == learning::MemoryError::Code::PARAMS_MISMATCH ||
        memory_result.error().code == learning::MemoryError::Code::CORRUPT;
    fail(memory_result.error().to_string(), bad_input ? EXIT_BAD_INPUT : EXIT_FAILURE_GENERIC);
  }
  for (const std::string& warning : memory_result->open_warnings()) {
    std::cerr << "orthoflow memory: warning: " << o.db << ": " << warning << '\n';
  }
  return std::move(memory_result).value();
}

// The descriptor of one object PCD under the store's specification, as a view record (object frame
// and bbox).
learning::ViewRecord view_of(const std::string& file, const kernels::DescriptorSpec& spec) {
  auto cloud_result = formats::read_pcd(file);
  if (!cloud_result) { fail(cloud_result.error().to_string(), EXIT_BAD_INPUT); }
  kernels::Describer describer(spec);
  learning::ViewRecord v;
  v.descriptor.assign(spec.length(), 0.0F);
  auto described = describer.describe(cloud_result->points(), v.descriptor);
  if (!described) { fail(file + ": " + kernels::to_string(described.error()), EXIT_BAD_INPUT); }
  v.frame = described->frame;
  v.bbox = described->bbox;
  v.stamp_ns = cloud_result->info.sensor_stamp_ns;
  return v;
}

void check_write(const learning::MemoryError& e) {
  fail(e.to_string(), e.code == learning::MemoryError::Code::REJECTED ||
                              e.code == learning::MemoryError::Code::BAD_IMPORT
                          ? EXIT_BAD_INPUT
                          : EXIT_FAILURE_GENERIC);
}

void run_teach(const MemoryOptions& o, bool correct) {
  auto memory = open_memory(o, learning::OpenMode::CREATE);
  std::vector<learning::ViewRecord> views;
  for (const std::string& f : o.files) { views.push_back(view_of(f, memory.config().descriptor)); }
  auto id_result = correct ? memory.correct(o.label, views.front()) : memory.teach(o.label, views);
  if (!id_result) { check_write(id_result.error()); }
  std::cout << (correct ? "corrected " : "taught ") << o.label << " (category " << *id_result
            << "): " << views.size() << " view" << (views.size() == 1 ? "" : "s") << ", synced\n";
}

nlohmann::json number_or_null(float v) {
  return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json(nullptr);
}

void run_ask(const MemoryOptions& o) {
  const auto memory = open_memory(o, learning::OpenMode::READ_ONLY);
  const learning::ViewRecord v = view_of(o.file, memory.config().descriptor);
  learning::AskScratch scratch;
  memory.learner().prepare(scratch);
  const learning::Prediction p = memory.learner().ask(v.descriptor, scratch);
  if (o.json) {
    const nlohmann::json j{{"label", p.unknown ? "" : std::string(p.label.view())},
                           {"best", std::string(p.label.view())},
                           {"score", number_or_null(p.score)},
                           {"unknown", p.unknown},
                           {"runner_up", std::string(p.runner_up.view())},
                           {"runner_up_score", number_or_null(p.runner_up_score)},
                           {"learner", memory.learner().kind()}};
    std::cout << j.dump() << '\n';
    return;
  }
  std::cout << (p.unknown ? "unknown" : std::string(p.label.view())) << " (score " << p.score
            << ", best " << p.label.view() << ", runner-up " << p.runner_up.view() << " "
            << p.runner_up_score << ")\n";
}

void run_list(const MemoryOptions& o) {
  const auto memory = open_memory(o, learning::OpenMode::READ_ONLY);
  for (const learning::CategoryEntry& c : memory.list()) {
    std::cout << c.id << '\t' << c.label << '\t' << c.views << '\n';
  }
}

void run_stats(const MemoryOptions& o) {
  const auto memory = open_memory(o, learning::OpenMode::READ_ONLY);
  const learning::MemoryStats s = memory.stats();
  const nlohmann::json j{{"categories", s.categories},
                         {"views", s.views},
                         {"descriptor_length", memory.learner().descriptor_length()},
                         {"learner", memory.learner().kind()},
                         {"stored_floats", s.learner.stored_floats}};
  std::cout << j.dump() << '\n';
}

void run_forget(const MemoryOptions& o) {
  auto memory = open_memory(o, learning::OpenMode::READ_WRITE);
  if (auto r = memory.forget(o.label); !r) {
    fail(r.error().to_string(), r.error().code == learning::MemoryError::Code::UNKNOWN_LABEL
                                    ? EXIT_BAD_INPUT
                                    : EXIT_FAILURE_GENERIC);
  }
  std::cout << "forgot " << o.label << '\n';
}

void run_transfer(const MemoryOptions& o, bool do_export) {
  auto memory =
      open_memory(o, do_export ? learning::OpenMode::READ_ONLY : learning::OpenMode::CREATE);
  auto count_result = do_export ? memory.export_to(o.file) : memory.import_from(o.file);
  if (!count_result) { check_write(count_result.error()); }
  std::cout << (do_export ? "exported " : "imported ") << *count_result << " views\n";
}

void run_calibrate(const MemoryOptions& o) {
  const auto memory = open_memory(o, learning::OpenMode::READ_ONLY);
  std::vector<std::vector<learning::ViewRecord>> views;
  std::vector<std::vector<float>> flat;
  std::vector<learning::RestoredCategory> cats;
  const std::size_t length = memory.learner().descriptor_length();
  const auto list = memory.list();
  for (const learning::CategoryEntry& c : list) {
    auto views_result = memory.views_of(c.id);
    if (!views_result) { fail(views_result.error().to_string(), EXIT_BAD_INPUT); }
    std::vector<float>& f = flat.emplace_back();
    for (const auto& v : *views_result) {
      f.insert(f.end(), v.descriptor.begin(), v.descriptor.end());
    }
  }
  for (std::size_t k = 0; k < list.size(); ++k) {
    cats.push_back({list[k].id, list[k].label, {flat[k], length}, {}, 0});
  }
  learning::InstanceConfig cfg = memory.config().instance;
  const auto calibration_result = learning::calibrate_threshold(cats, cfg);
  if (!calibration_result) {
    fail(learning::to_string(calibration_result.error()), EXIT_FAILURE_GENERIC);
  }
  std::cout << nlohmann::json{{"ct", calibration_result->threshold},
                              {"balanced_accuracy", calibration_result->balanced_accuracy},
                              {"known_samples", calibration_result->known_samples},
                              {"unknown_samples", calibration_result->unknown_samples}}
                   .dump()
            << '\n';
}

}  // namespace

void add_memory_command(CLI::App& app) {
  auto* cmd = app.add_subcommand(
      "memory", "Perceptual memory (LevelDB): teach, ask, correct, list, forget, export");
  auto o = std::make_shared<MemoryOptions>();
  cmd->add_option("--db", o->db, "memory directory (created if missing)")->required();
  cmd->add_option("--learner", o->learner, "instance (NOCD, approach I) or bayes (naive Bayes)")
      ->check(CLI::IsMember({"instance", "bayes"}));
  cmd->add_option("--bins", o->bins, "GOOD bins per side; must match the store (default 15)")
      ->check(CLI::Range(std::size_t{1}, kernels::GOOD_MAX_BINS));
  cmd->add_option("--representation", o->representation,
                  "good, spin (sets of spin images, instance-based), bow (a bag of words), lda "
                  "(its topics) or local-lda (word counts, topics learned per category); a new "
                  "store of the last three needs --dictionary, an existing one uses its own")
      ->check(CLI::IsMember({"good", "spin", "bow", "lda", "local-lda"}));
  add_spin_set_options(cmd, o->spin);
  cmd->add_option(
      "--dictionary", o->dictionary,
      "bow, lda: the visual words (`orthoflow dictionary build`); implies bow unless lda");
  cmd->add_option("--mode", o->mode, "GOOD frame mode; must match the store")
      ->check(CLI::IsMember({"invariant", "reference"}));
  cmd->add_option("--ct", o->ct,
                  "classification threshold CT (instance learner; default: never unknown)")
      ->check(CLI::Range(0.0F, 1e9F));
  cmd->require_subcommand(1);
  cmd->fallthrough();
  auto* teach =
      cmd->add_subcommand("teach", "Store the views of FILE.pcd... under LABEL (one synced write)");
  teach->add_option("label", o->label, "category label (1-63 bytes)")
      ->required()
      ->transform(composed_label());
  teach->add_option("files", o->files, "object PCD files")->required()->check(CLI::ExistingFile);
  teach->callback([o] { run_teach(*o, false); });
  auto* correct = cmd->add_subcommand("correct", "Store one view after a wrong answer");
  correct->add_option("label", o->label, "the right label")
      ->required()
      ->transform(composed_label());
  correct->add_option("file", o->files, "object PCD file")
      ->required()
      ->expected(1)
      ->check(CLI::ExistingFile);
  correct->callback([o] { run_teach(*o, true); });
  auto* ask = cmd->add_subcommand("ask", "Recognise the object in FILE.pcd");
  ask->add_option("file", o->file, "object PCD file")->required();
  ask->add_flag("--json", o->json, "print {label, score, unknown, runner_up, ...}");
  ask->callback([o] { run_ask(*o); });
  cmd->add_subcommand("list", "Categories: id, label, views")->callback([o] { run_list(*o); });
  cmd->add_subcommand("stats", "Totals as JSON")->callback([o] { run_stats(*o); });
  auto* forget = cmd->add_subcommand("forget", "Delete a category and its views");
  forget->add_option("label", o->label, "category label")->required()->transform(composed_label());
  forget->callback([o] { run_forget(*o); });
  auto* exp = cmd->add_subcommand("export", "Write the memory as JSON lines");
  exp->add_option("file", o->file, "output file")->required();
  exp->callback([o] { run_transfer(*o, true); });
  auto* imp = cmd->add_subcommand("import", "Teach every view of a JSON-lines export");
  imp->add_option("file", o->file, "export file")->required();
  imp->callback([o] { run_transfer(*o, false); });
  cmd->add_subcommand("calibrate", "Leave-one-out CT for the instance learner (docs/LEARNING.md)")
      ->callback([o] { run_calibrate(*o); });
}

}  // namespace orthoflow::apps
