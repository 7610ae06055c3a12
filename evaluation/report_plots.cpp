// The human-facing half of the report: the Markdown summary table and the plots.
#include <cstdio>
#include <sstream>

#include "evaluation/report.hpp"

namespace orthoflow::evaluation {
namespace {

std::string fixed(double v, int digits) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.*f", digits, v);
  return buf;
}

template <class F>
std::string mean_pm(const std::vector<TeacherRun>& runs, F field, int digits) {
  std::vector<double> values;
  for (const TeacherRun& t : runs) { values.push_back(static_cast<double>(field(t))); }
  const MeanStd m = mean_std(values);
  return fixed(m.mean, digits) + " ± " + fixed(m.std, digits);
}

std::string stops(const std::vector<TeacherRun>& runs) {
  std::size_t breakpoint = 0;
  for (const TeacherRun& t : runs) { breakpoint += t.stop == TeacherStop::BREAKPOINT ? 1 : 0; }
  return std::to_string(breakpoint) + " breakpoint, " + std::to_string(runs.size() - breakpoint) +
         " lack of data";
}

void cv_rows(std::ostringstream& md, const Evaluation& e) {
  md << "| variant | accuracy | micro precision | micro recall | macro precision | macro recall "
        "|\n|---|---|---|---|---|---|\n";
  for (const VariantResult& v : e.variants) {
    std::vector<double> acc, mp, mr, Mp, Mr;
    for (const CvResult& cv : v.cv) {
      acc.push_back(cv.scores.accuracy);
      mp.push_back(cv.scores.micro_precision);
      mr.push_back(cv.scores.micro_recall);
      Mp.push_back(cv.scores.macro_precision);
      Mr.push_back(cv.scores.macro_recall);
    }
    md << "| " << v.variant.name();
    for (const auto* values : {&acc, &mp, &mr, &Mp, &Mr}) {
      const MeanStd m = mean_std(*values);
      md << " | " << fixed(m.mean, 3) << " ± " << fixed(m.std, 3);
    }
    md << " |\n";
  }
}

void teacher_rows(std::ostringstream& md, const Evaluation& e) {
  md << "| variant | NLC | QCI | AIC | GCA | APA | stopping condition "
        "|\n|---|---|---|---|---|---|---|\n";
  for (const VariantResult& v : e.variants) {
    md << "| " << v.variant.name() << " | "
       << mean_pm(
              v.teacher, [](const TeacherRun& t) { return t.nlc; }, 1)
       << " | "
       << mean_pm(
              v.teacher, [](const TeacherRun& t) { return t.qci; }, 0)
       << " | "
       << mean_pm(
              v.teacher, [](const TeacherRun& t) { return t.aic; }, 2)
       << " | "
       << mean_pm(
              v.teacher, [](const TeacherRun& t) { return t.gca; }, 3)
       << " | "
       << mean_pm(
              v.teacher, [](const TeacherRun& t) { return t.apa; }, 3)
       << " | " << stops(v.teacher) << " |\n";
  }
}

void context_rows(std::ostringstream& md, const Evaluation& e) {
  md << "| variant | ALC (no change) | rho | ALC_A | ALC_B | adaptability | stopping condition "
        "|\n|---|---|---|---|---|---|---|\n";
  for (const VariantResult& v : e.variants) {
    double a = 0.0, b = 0.0, rho = 0.0;
    std::size_t n = 0;
    for (std::size_t r = 0; r < v.context.size(); ++r) {
      rho += static_cast<double>(v.rho[r]) / static_cast<double>(v.context.size());
      if (v.context[r].switched && v.context[r].stop == TeacherStop::BREAKPOINT) {
        a += static_cast<double>(v.context[r].learned_a);
        b += static_cast<double>(v.context[r].learned_b);
        ++n;
      }
    }
    md << "| " << v.variant.name() << " | " << fixed(v.alc, 1) << " | " << fixed(rho, 1) << " | "
       << mean_pm(
              v.context, [](const TeacherRun& t) { return t.learned_a; }, 1)
       << " | "
       << mean_pm(
              v.context, [](const TeacherRun& t) { return t.learned_b; }, 1)
       << " | "
       << (n == 0 || a == 0.0 ? std::string("n/a (no run ended at the breakpoint after switching)")
                              : fixed(b / a, 3) + " (" + std::to_string(n) + " runs)")
       << " | " << stops(v.context) << " |\n";
  }
}

void level_rows(std::ostringstream& md, const Evaluation& e) {
  if (e.variants.empty() || e.variants[0].levels.empty()) { return; }
  md << "| variant";
  for (const LevelResult& l : e.variants[0].levels) {
    md << " | "
       << (l.amount_m == 0.0 ? std::string("clean") : fixed(l.amount_m * 1000.0, 0) + " mm");
  }
  md << " |\n|---";
  for (std::size_t i = 0; i < e.variants[0].levels.size(); ++i) { md << "|---"; }
  md << "|\n";
  for (const VariantResult& v : e.variants) {
    md << "| " << v.variant.name();
    for (const LevelResult& l : v.levels) { md << " | " << fixed(mean_std(l.accuracy).mean, 3); }
    md << " |\n";
  }
}

/// Mean GCA over runs at each learned-category count reached by at least one run.
Series gca_series(const VariantResult& v) {
  Series s{v.variant.name(), {}, {}, {}, true};
  for (std::size_t k = 1;; ++k) {
    std::vector<double> at_k;
    for (const TeacherRun& t : v.teacher) {
      if (t.curve.size() >= k && k >= 2) { at_k.push_back(t.curve[k - 1].gca); }
    }
    if (k >= 2 && at_k.empty()) { break; }
    if (at_k.empty()) { continue; }
    const MeanStd m = mean_std(at_k);
    s.x.push_back(static_cast<double>(k));
    s.y.push_back(m.mean);
    s.y_err.push_back(m.std);
  }
  return s;
}

/// Learned categories against iterations of one run, as a staircase ending at the last iteration.
Series learning_series(const std::string& name, const TeacherRun& run) {
  Series s{name, {}, {}, {}, false};
  for (const LearnedPoint& p : run.curve) {
    if (!s.x.empty()) {
      s.x.push_back(static_cast<double>(p.iteration));
      s.y.push_back(s.y.back());
    }
    s.x.push_back(static_cast<double>(p.iteration));
    s.y.push_back(static_cast<double>(p.learned));
  }
  if (!s.x.empty() && run.qci > run.curve.back().iteration) {
    s.x.push_back(static_cast<double>(run.qci));
    s.y.push_back(s.y.back());
  }
  return s;
}

}  // namespace

std::string summary_markdown(const Evaluation& e) {
  std::ostringstream md;
  md << "### " << to_string(e.options.protocol) << ": " << e.categories.size() << " categories, "
     << e.instances << " instances, " << e.views << " views; " << e.options.runs << " runs, seed "
     << e.options.seed;
  if (e.options.protocol == Protocol::TEACHER || e.options.protocol == Protocol::TEACHER_CONTEXT) {
    md << "; tau " << fixed(e.options.teacher.tau, 2) << ", breakpoint "
       << e.options.teacher.breakpoint;
  }
  md << "\n\n";
  switch (e.options.protocol) {
    case Protocol::CV10:
      cv_rows(md, e);
      break;
    case Protocol::TEACHER:
      teacher_rows(md, e);
      break;
    case Protocol::TEACHER_CONTEXT:
      teacher_rows(md, e);
      md << "\n";
      context_rows(md, e);
      break;
    case Protocol::NOISE:
    case Protocol::DOWNSAMPLE:
      level_rows(md, e);
      break;
  }
  md << "\nValues are mean ± sample standard deviation over runs (accuracy columns of robustness "
        "tables: means).\n";
  return md.str();
}

std::vector<std::pair<std::string, PlotSpec>> evaluation_plots(const Evaluation& e) {
  std::vector<std::pair<std::string, PlotSpec>> plots;
  const Protocol p = e.options.protocol;
  if ((p == Protocol::TEACHER || p == Protocol::TEACHER_CONTEXT) && !e.variants.empty()) {
    PlotSpec learned{"Learned categories vs question/correction iterations (run 1)",
                     "question/correction iterations",
                     "learned categories",
                     {},
                     std::nullopt,
                     std::nullopt,
                     800,
                     500};
    PlotSpec gca{"Global classification accuracy vs learned categories (mean ± std over runs)",
                 "learned categories",
                 "global accuracy",
                 {},
                 0.0,
                 1.0,
                 800,
                 500};
    PlotSpec context{"Context change: learned categories vs iterations (run 1)",
                     "question/correction iterations",
                     "learned categories",
                     {},
                     std::nullopt,
                     std::nullopt,
                     800,
                     500};
    for (const VariantResult& v : e.variants) {
      learned.series.push_back(learning_series(v.variant.name(), v.teacher.front()));
      gca.series.push_back(gca_series(v));
      if (!v.context.empty()) {
        context.series.push_back(learning_series(
            v.variant.name() + " (A: " + std::to_string(v.rho.front()) + ")", v.context.front()));
      }
    }
    plots.emplace_back("learned_categories", std::move(learned));
    plots.emplace_back("accuracy_vs_learned", std::move(gca));
    if (p == Protocol::TEACHER_CONTEXT) {
      plots.emplace_back("learned_categories_context", std::move(context));
    }
  }
  if (p == Protocol::NOISE || p == Protocol::DOWNSAMPLE) {
    const bool noise = p == Protocol::NOISE;
    PlotSpec acc{
        noise ? "Accuracy vs Gaussian noise on test views" : "Accuracy vs voxel size of test views",
        noise ? "noise sigma (mm)" : "voxel size (mm)",
        "accuracy",
        {},
        0.0,
        1.0,
        800,
        500};
    for (const VariantResult& v : e.variants) {
      Series s{v.variant.name(), {}, {}, {}, true};
      for (const LevelResult& l : v.levels) {
        const MeanStd m = mean_std(l.accuracy);
        s.x.push_back(l.amount_m * 1000.0);
        s.y.push_back(m.mean);
        s.y_err.push_back(m.std);
      }
      acc.series.push_back(std::move(s));
    }
    plots.emplace_back(noise ? "accuracy_vs_noise" : "accuracy_vs_downsampling", std::move(acc));
  }
  return plots;
}

}  // namespace orthoflow::evaluation
