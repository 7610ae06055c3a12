#include "evaluation/experiment.hpp"

#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <chrono>
#include <cmath>
#include <map>

#include "core/rng.hpp"
#include "evaluation/progress.hpp"

namespace orthoflow::evaluation {
namespace {

EvalError config_error(std::string m) {
  return EvalError{EvalError::Code::BAD_CONFIG, std::move(m)};
}

bool perturbed(Protocol p) { return p == Protocol::NOISE || p == Protocol::DOWNSAMPLE; }

/// The seed of run @p r: every random choice of a run derives from it, never from the variant.
std::uint64_t run_seed(std::uint64_t seed, std::size_t r) {
  return seed * 0x9E3779B97F4A7C15ULL + r * 0xBF58476D1CE4E5B9ULL + 1;
}

Result<void, EvalError> check(const Dataset& ds, const EvalOptions& o) {
  if (o.variants.empty()) { return err(config_error("no variant to evaluate")); }
  if (o.runs == 0 || o.runs > 1000) {
    return err(config_error("runs must be in 1..1000, got " + std::to_string(o.runs)));
  }
  if (o.folds < 2) {
    return err(config_error("folds must be at least 2, got " + std::to_string(o.folds)));
  }
  for (const double l : protocol_levels(o)) {
    if (!std::isfinite(l) || l <= 0.0 || l > 1.0) {
      return err(config_error("levels must be in (0, 1] m, got " + std::to_string(l)));
    }
  }
  if (o.teacher.intro_views == 0 || o.teacher.breakpoint == 0 ||
      !(o.teacher.tau >= 0.0 && o.teacher.tau < 1.0)) {
    return err(config_error("teacher needs intro views >= 1, breakpoint >= 1 and tau in [0, 1)"));
  }
  const bool teacher = o.protocol == Protocol::TEACHER || o.protocol == Protocol::TEACHER_CONTEXT;
  // Algorithm 7.1 measures how many categories a learner tells apart: a learner that knows one
  // category has none to tell apart, so no question is asked and no accuracy is measured.
  if (teacher && ds.categories.size() < 2) {
    return err(EvalError{EvalError::Code::TOO_FEW_CATEGORIES,
                         "the teacher protocol needs at least 2 categories, the dataset has " +
                             std::to_string(ds.categories.size()) +
                             (ds.categories.empty() ? "" : " ('" + ds.categories[0] + "')") +
                             ": a learner that knows one category has none to tell apart"});
  }
  for (std::uint32_t c = 0; teacher && c < ds.categories.size(); ++c) {
    if (ds.views_of(c).size() <= o.teacher.intro_views) {
      return err(EvalError{EvalError::Code::TOO_FEW_VIEWS,
                           "category '" + ds.categories[c] + "' has " +
                               std::to_string(ds.views_of(c).size()) +
                               " views; the teacher needs more than the " +
                               std::to_string(o.teacher.intro_views) + " it teaches"});
    }
  }
  if (o.protocol == Protocol::TEACHER_CONTEXT && ds.categories.size() < 3) {
    return err(
        EvalError{EvalError::Code::TOO_FEW_CATEGORIES,
                  "the context change protocol needs at least 3 categories, the dataset has " +
                      std::to_string(ds.categories.size())});
  }
  return {};
}

/// Descriptor tables shared by variants with the same (mode, bins), computed once each.
class Tables {
 public:
  Tables(const Dataset& ds, const EvalOptions& o, Progress* p, Evaluation& e)
      : ds_(ds), o_(o), p_(p), e_(e) {}
  Result<const DescriptorTable*, EvalError> get(const ViewDescription& spec) {
    const std::string key = spec.key();
    if (const auto it = tables_.find(key); it != tables_.end()) { return &it->second; }
    DescribeStats stats;
    auto t = describe_dataset(ds_, spec, o_.cache_dir, p_, &stats, &e_.warnings);
    if (!t) { return err(t.error()); }
    e_.describe.computed += stats.computed;
    e_.describe.cached += stats.cached;
    return &tables_.emplace(key, std::move(*t)).first->second;
  }

 private:
  const Dataset& ds_;
  const EvalOptions& o_;
  Progress* p_;
  Evaluation& e_;
  std::map<std::string, DescriptorTable> tables_;
};

void tick(Progress* p) {
  if (p != nullptr) { p->advance(); }
}

/// The fold split of every run (seeded by the run, shared by every variant and level).
Result<std::vector<Folds>, EvalError> folds_per_run(const Dataset& ds, const EvalOptions& o) {
  std::vector<Folds> folds;
  for (std::size_t r = 0; r < o.runs; ++r) {
    auto f = make_folds(ds, o.folds, run_seed(o.seed, r));
    if (!f) { return err(f.error()); }
    folds.push_back(std::move(*f));
  }
  return folds;
}

Result<void, EvalError> run_cv(const Dataset& ds, const EvalOptions& o, Tables& tables,
                               Evaluation& e, Progress* p) {
  auto run_folds = folds_per_run(ds, o);
  if (!run_folds) { return err(run_folds.error()); }
  const std::vector<Folds>& folds = *run_folds;
  for (VariantResult& vr : e.variants) {
    auto t = tables.get(vr.variant.descriptor());
    if (!t) { return err(t.error()); }
    vr.cv.resize(o.runs);
    tbb::parallel_for(std::size_t{0}, o.runs, [&](std::size_t r) {
      vr.cv[r] = cross_validate(ds, folds[r], **t, **t, vr.variant);
      tick(p);
    });
  }
  return {};
}

Result<void, EvalError> run_levels(const Dataset& ds, const EvalOptions& o, Tables& tables,
                                   Evaluation& e, Progress* p) {
  const Perturbation kind =
      o.protocol == Protocol::NOISE ? Perturbation::NOISE : Perturbation::DOWNSAMPLE;
  std::vector<double> levels{0.0};
  for (const double l : protocol_levels(o)) { levels.push_back(l); }
  auto run_folds = folds_per_run(ds, o);
  if (!run_folds) { return err(run_folds.error()); }
  const std::vector<Folds>& folds = *run_folds;
  for (VariantResult& vr : e.variants) {
    auto clean = tables.get(vr.variant.descriptor());
    if (!clean) { return err(clean.error()); }
    for (const double level : levels) {
      auto test = level == 0.0 ? clean : tables.get(vr.variant.descriptor(kind, level, o.seed));
      if (!test) { return err(test.error()); }
      LevelResult lr{level, std::vector<double>(o.runs, 0.0)};
      tbb::parallel_for(std::size_t{0}, o.runs, [&](std::size_t r) {
        lr.accuracy[r] = cross_validate(ds, folds[r], **clean, **test, vr.variant).scores.accuracy;
        tick(p);
      });
      vr.levels.push_back(std::move(lr));
    }
  }
  return {};
}

void run_teachers(const Dataset& ds, const EvalOptions& o, const DescriptorTable& t,
                  VariantResult& vr, Progress* p) {
  vr.teacher.resize(o.runs);
  tbb::parallel_for(std::size_t{0}, o.runs, [&](std::size_t r) {
    const std::vector<std::uint32_t> order =
        category_order(ds.categories.size(), run_seed(o.seed, r));
    vr.teacher[r] = run_teacher(ds, t, vr.variant, order, o.teacher, run_seed(o.seed, r) + 7);
    tick(p);
  });
  double sum = 0.0;
  for (const TeacherRun& run : vr.teacher) { sum += static_cast<double>(run.nlc); }
  vr.alc = sum / static_cast<double>(o.runs);
}

/// Thesis 7.3.1: rho drawn uniformly in [0.65, 0.85] x ALC, kept within [1, categories - 1].
std::size_t draw_rho(const EvalOptions& o, std::size_t r, double alc, std::size_t categories) {
  core::Rng rng(run_seed(o.seed, r) ^ 0x5851F42D4C957F2DULL);
  const double u = 0.65 + 0.2 * rng.uniform();
  const auto rho = static_cast<std::size_t>(std::llround(u * alc));
  return std::clamp<std::size_t>(rho, 1, categories - 1);
}

void run_context(const Dataset& ds, const EvalOptions& o, const DescriptorTable& t,
                 VariantResult& vr, Progress* p) {
  vr.context.resize(o.runs);
  vr.rho.resize(o.runs);
  for (std::size_t r = 0; r < o.runs; ++r) {
    vr.rho[r] = draw_rho(o, r, vr.alc, ds.categories.size());
  }
  tbb::parallel_for(std::size_t{0}, o.runs, [&](std::size_t r) {
    const std::vector<std::uint32_t> order =
        category_order(ds.categories.size(), run_seed(o.seed, r) + 1);
    TeacherConfig cfg = o.teacher;
    cfg.context_a = vr.rho[r];
    vr.context[r] = run_teacher(ds, t, vr.variant, order, cfg, run_seed(o.seed, r) + 11);
    tick(p);
  });
}

}  // namespace

const char* to_string(Protocol p) noexcept {
  switch (p) {
    case Protocol::CV10:
      return "cv10";
    case Protocol::TEACHER:
      return "teacher";
    case Protocol::TEACHER_CONTEXT:
      return "teacher-context";
    case Protocol::NOISE:
      return "noise";
    case Protocol::DOWNSAMPLE:
      return "downsample";
  }
  return "?";
}

std::vector<double> protocol_levels(const EvalOptions& o) {
  if (!o.levels_m.empty() || !perturbed(o.protocol)) { return o.levels_m; }
  if (o.protocol == Protocol::NOISE) {
    return {0.001, 0.002, 0.003, 0.004, 0.005, 0.006, 0.007, 0.008, 0.009, 0.010};
  }
  return {0.001, 0.002, 0.004, 0.006, 0.008, 0.010, 0.012, 0.014, 0.016, 0.018, 0.020};
}

std::size_t evaluation_work(const Dataset& ds, const EvalOptions& o) {
  std::map<std::string, int> specs;
  for (const Variant& v : o.variants) { specs[v.descriptor().key()] = 1; }
  const std::size_t levels = perturbed(o.protocol) ? protocol_levels(o).size() + 1 : 1;
  const std::size_t tables = specs.size() * levels;
  const std::size_t per_run = o.protocol == Protocol::TEACHER_CONTEXT ? 2 : levels;
  return tables * ds.views.size() + o.variants.size() * o.runs * per_run;
}

Result<Evaluation, EvalError> evaluate(const Dataset& ds, const EvalOptions& o, Progress* p) {
  if (auto ok = check(ds, o); !ok) { return err(ok.error()); }
  const auto start = std::chrono::steady_clock::now();
  Evaluation e{o, ds.categories, ds.views.size(), ds.instances.size(), {}, {}, {}, 0.0};
  for (const Variant& v : o.variants) {
    e.variants.push_back(VariantResult{v, {}, {}, {}, {}, 0.0, {}});
  }
  tbb::task_arena arena(o.threads == 0 ? tbb::task_arena::automatic : static_cast<int>(o.threads));
  Result<void, EvalError> outcome;
  arena.execute([&] {
    Tables tables(ds, o, p, e);
    if (o.protocol == Protocol::CV10) {
      outcome = run_cv(ds, o, tables, e, p);
      return;
    }
    if (perturbed(o.protocol)) {
      outcome = run_levels(ds, o, tables, e, p);
      return;
    }
    for (VariantResult& vr : e.variants) {
      auto t = tables.get(vr.variant.descriptor());
      if (!t) {
        outcome = err(t.error());
        return;
      }
      run_teachers(ds, o, **t, vr, p);
      if (o.protocol == Protocol::TEACHER_CONTEXT) { run_context(ds, o, **t, vr, p); }
    }
  });
  if (!outcome) { return err(outcome.error()); }
  e.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return e;
}

}  // namespace orthoflow::evaluation
