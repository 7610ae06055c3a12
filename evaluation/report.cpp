#include "evaluation/report.hpp"
#include "core/file_output.hpp"

#include <cstdio>
#include <fstream>
#include <nlohmann/json.hpp>

namespace orthoflow::evaluation {
namespace {

using nlohmann::json;

json scores_json(const Scores& s) {
  return {{"accuracy", s.accuracy},
          {"micro_precision", s.micro_precision},
          {"micro_recall", s.micro_recall},
          {"macro_precision", s.macro_precision},
          {"macro_recall", s.macro_recall},
          {"answers", s.answers},
          {"unknown", s.unknown}};
}

json teacher_json(const TeacherRun& t) {
  json curve = json::array();
  for (const LearnedPoint& p : t.curve) { curve.push_back({p.iteration, p.learned, p.gca}); }
  return {{"nlc", t.nlc},
          {"qci", t.qci},
          {"aic", t.aic},
          {"gca", t.gca},
          {"apa", t.apa},
          {"stop", to_string(t.stop)},
          {"learned_a", t.learned_a},
          {"learned_b", t.learned_b},
          {"switched", t.switched},
          {"curve_iteration_learned_gca", curve}};
}

json cv_json(const VariantResult& v) {
  json runs = json::array();
  std::vector<std::size_t> confusion;
  for (const CvResult& cv : v.cv) {
    runs.push_back({{"scores", scores_json(cv.scores)}, {"fold_accuracy", cv.fold_accuracy}});
    if (confusion.empty()) { confusion.assign(cv.confusion.counts.size(), 0); }
    for (std::size_t i = 0; i < confusion.size(); ++i) { confusion[i] += cv.confusion.counts[i]; }
  }
  return {{"runs", runs}, {"confusion_summed_over_runs", confusion}};
}

/// Adaptability = mean ALC_B / mean ALC_A over runs that switched context and ended at the
/// breakpoint (thesis 7.3.1: a run ended by lack of data cannot measure it); null when there is
/// none.
json adaptability(const VariantResult& v) {
  double a = 0.0, b = 0.0;
  std::size_t n = 0;
  for (const TeacherRun& t : v.context) {
    if (t.switched && t.stop == TeacherStop::BREAKPOINT) {
      a += static_cast<double>(t.learned_a);
      b += static_cast<double>(t.learned_b);
      ++n;
    }
  }
  if (n == 0 || a == 0.0) { return nullptr; }
  return {{"value", b / a}, {"runs_used", n}};
}

json variant_json(const VariantResult& v) {
  json j{{"name", v.variant.name()}};
  if (!v.cv.empty()) { j["cv"] = cv_json(v); }
  if (!v.teacher.empty()) {
    j["teacher"] = json::array();
    for (const TeacherRun& t : v.teacher) { j["teacher"].push_back(teacher_json(t)); }
    j["alc"] = v.alc;
  }
  if (!v.context.empty()) {
    j["context"] = json::array();
    for (std::size_t r = 0; r < v.context.size(); ++r) {
      json t = teacher_json(v.context[r]);
      t["rho"] = v.rho[r];
      j["context"].push_back(t);
    }
    j["adaptability"] = adaptability(v);
  }
  for (const LevelResult& l : v.levels) {
    j["levels"].push_back({{"amount_m", l.amount_m}, {"accuracy", l.accuracy}});
  }
  return j;
}

Result<void, EvalError> write_text(const std::filesystem::path& path, const std::string& text) {
  if (auto written = core::write_whole_file(path, text); !written) {
    return err(EvalError{EvalError::Code::WRITE_FAILED, "cannot write " + written.error()});
  }
  return {};
}

}  // namespace

std::string results_json(const Evaluation& e) {
  const EvalOptions& o = e.options;
  json j{{"protocol", to_string(o.protocol)},
         {"runs", o.runs},
         {"seed", o.seed},
         {"folds", o.folds},
         {"levels_m", protocol_levels(o)},
         {"tau", o.teacher.tau},
         {"breakpoint", o.teacher.breakpoint},
         {"intro_views", o.teacher.intro_views},
         {"categories", e.categories},
         {"views", e.views},
         {"instances", e.instances},
         {"descriptors_computed", e.describe.computed},
         {"descriptors_cached", e.describe.cached},
         {"seconds", e.seconds},
         {"warnings", e.warnings}};
  j["variants"] = json::array();
  for (const VariantResult& v : e.variants) { j["variants"].push_back(variant_json(v)); }
  return j.dump(1) + "\n";
}

Result<std::vector<std::filesystem::path>, EvalError> write_report(
    const Evaluation& e, const std::filesystem::path& out) {
  std::error_code ec;
  std::filesystem::create_directories(out, ec);
  if (ec) {
    return err(EvalError{EvalError::Code::WRITE_FAILED,
                         "cannot create " + out.string() + ": " + ec.message()});
  }
  std::vector<std::filesystem::path> written{out / "results.json", out / "summary.md"};
  if (auto r = write_text(written[0], results_json(e)); !r) { return err(r.error()); }
  if (auto r = write_text(written[1], summary_markdown(e)); !r) { return err(r.error()); }
  for (const auto& [stem, spec] : evaluation_plots(e)) {
    for (const char* ext : {".png", ".svg"}) {
      const std::filesystem::path path = out / (stem + ext);
      auto r = ext[1] == 'p' ? write_plot_png(spec, path) : write_plot_svg(spec, path);
      if (!r) { return err(EvalError{EvalError::Code::WRITE_FAILED, r.error().to_string()}); }
      written.push_back(path);
    }
  }
  return written;
}

}  // namespace orthoflow::evaluation
