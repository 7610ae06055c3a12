// evaluate(): the same seed gives the same results for any thread count, variants share folds and
// orders, the context protocol derives rho from ALC, and the report writes its files.
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include "evaluation/experiment.hpp"
#include "evaluation/report.hpp"
#include "tests/evaluation/box_dataset.hpp"
#include "tests/evaluation/eval_fixtures.hpp"

namespace orthoflow::evaluation {
namespace {

namespace fs = std::filesystem;

class Experiment : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    root_ = new fs::path(testing::unique_dir("experiment"));
    testing::write_box_dataset(*root_, 4, 2, 6);
  }
  static void TearDownTestSuite() {
    fs::remove_all(*root_);
    delete root_;
  }
  static Dataset dataset() { return scan_dataset(*root_).value(); }
  static EvalOptions options(Protocol p, std::size_t threads) {
    EvalOptions o;
    o.protocol = p;
    Variant bayes;
    bayes.learner = LearnerKind::BAYES;
    bayes.bins = 5;
    Variant nn;
    nn.bins = 5;
    o.variants = {nn, bayes};
    o.runs = 4;
    o.seed = 11;
    o.folds = 4;
    o.threads = threads;
    o.levels_m = {0.002, 0.02};
    return o;
  }
  /// results.json without the wall time.
  static std::string stable_json(const Evaluation& e) {
    auto j = nlohmann::json::parse(results_json(e));
    j.erase("seconds");
    return j.dump();
  }
  static fs::path* root_;
};
fs::path* Experiment::root_ = nullptr;

TEST_F(Experiment, SameSeedSameResultsForAnyThreadCount) {
  const Dataset ds = dataset();
  for (const Protocol p : {Protocol::CV10, Protocol::TEACHER, Protocol::TEACHER_CONTEXT,
                           Protocol::NOISE, Protocol::DOWNSAMPLE}) {
    auto one = evaluate(ds, options(p, 1), nullptr);
    auto two = evaluate(ds, options(p, 2), nullptr);
    ASSERT_TRUE(one && two) << to_string(p);
    EXPECT_EQ(stable_json(*one), stable_json(*two)) << to_string(p);
    EvalOptions other_seed = options(p, 2);
    other_seed.seed = 12;
    auto three = evaluate(ds, other_seed, nullptr);
    ASSERT_TRUE(three);
    if (p != Protocol::DOWNSAMPLE && p != Protocol::NOISE) {
      EXPECT_NE(stable_json(*one), stable_json(*three)) << to_string(p);
    }
  }
}

TEST_F(Experiment, VariantsShareTheRandomChoices) {
  const Dataset ds = dataset();
  EvalOptions o = options(Protocol::TEACHER, 2);
  Variant same = o.variants[0];
  o.variants = {same, same};
  auto e = evaluate(ds, o, nullptr);
  ASSERT_TRUE(e);
  for (std::size_t r = 0; r < o.runs; ++r) {
    EXPECT_EQ(e->variants[0].teacher[r].qci, e->variants[1].teacher[r].qci);
    EXPECT_EQ(e->variants[0].teacher[r].gca, e->variants[1].teacher[r].gca);
  }
}

TEST_F(Experiment, ContextSizeFollowsAlc) {
  const Dataset ds = dataset();
  auto e = evaluate(ds, options(Protocol::TEACHER_CONTEXT, 2), nullptr);
  ASSERT_TRUE(e);
  for (const VariantResult& v : e->variants) {
    ASSERT_EQ(v.rho.size(), 4U);
    for (const std::size_t rho : v.rho) {
      EXPECT_GE(static_cast<double>(rho), std::max(1.0, std::floor(0.65 * v.alc) - 1.0));
      EXPECT_LE(static_cast<double>(rho), std::min(3.0, std::ceil(0.85 * v.alc)));
    }
    for (const TeacherRun& t : v.context) { EXPECT_EQ(t.nlc, t.learned_a + t.learned_b); }
  }
}

TEST_F(Experiment, RobustnessLevelsStartClean) {
  auto e = evaluate(dataset(), options(Protocol::NOISE, 2), nullptr);
  ASSERT_TRUE(e);
  const auto& levels = e->variants[0].levels;
  ASSERT_EQ(levels.size(), 3U);
  EXPECT_EQ(levels[0].amount_m, 0.0);
  EXPECT_EQ(levels[2].amount_m, 0.02);
  // 2 cm of noise on boxes a few cm wide destroys them: accuracy falls from the clean level.
  EXPECT_GT(levels[0].accuracy[0], levels[2].accuracy[0]);
}

TEST_F(Experiment, ConfigurationErrors) {
  const Dataset ds = dataset();
  EvalOptions o = options(Protocol::CV10, 1);
  o.runs = 0;
  EXPECT_EQ(evaluate(ds, o, nullptr).error().code, EvalError::Code::BAD_CONFIG);
  o = options(Protocol::NOISE, 1);
  o.levels_m = {-0.001};
  EXPECT_EQ(evaluate(ds, o, nullptr).error().code, EvalError::Code::BAD_CONFIG);
  o = options(Protocol::TEACHER, 1);
  o.teacher.intro_views = 12;  // every category has exactly 12 views: nothing left to ask
  EXPECT_EQ(evaluate(ds, o, nullptr).error().code, EvalError::Code::TOO_FEW_VIEWS);
  o = options(Protocol::CV10, 1);
  o.variants.clear();
  EXPECT_EQ(evaluate(ds, o, nullptr).error().code, EvalError::Code::BAD_CONFIG);
  // Issue 16: one category under the teacher used to fail writing its plots ("no series"); it is
  // refused up front, as two under the context change are.
  const auto one = testing::hand_made({{"mug", 12, {1.0F, 0.0F, 0.0F}}});
  auto single = evaluate(one.dataset, options(Protocol::TEACHER, 1), nullptr);
  ASSERT_FALSE(single);
  EXPECT_EQ(single.error().code, EvalError::Code::TOO_FEW_CATEGORIES);
  EXPECT_NE(single.error().to_string().find("too_few_categories: the teacher protocol needs at "
                                            "least 2 categories, the dataset has 1 ('mug')"),
            std::string::npos)
      << single.error().to_string();
  const auto two =
      testing::hand_made({{"a", 12, {1.0F, 0.0F, 0.0F}}, {"b", 12, {0.0F, 1.0F, 0.0F}}});
  EXPECT_EQ(evaluate(two.dataset, options(Protocol::TEACHER_CONTEXT, 1), nullptr).error().code,
            EvalError::Code::TOO_FEW_CATEGORIES);
}

TEST_F(Experiment, ReportWritesJsonMarkdownAndPlots) {
  const fs::path out = testing::unique_dir("report");
  auto e = evaluate(dataset(), options(Protocol::TEACHER_CONTEXT, 2), nullptr);
  ASSERT_TRUE(e);
  auto written = write_report(*e, out / "sub");
  ASSERT_TRUE(written) << written.error().to_string();
  EXPECT_EQ(written->size(), 8U);  // json, md, 3 plots x (png, svg)
  for (const fs::path& f : *written) { EXPECT_GT(fs::file_size(f), 100U) << f; }
  const auto j = nlohmann::json::parse(results_json(*e));
  EXPECT_EQ(j["protocol"], "teacher-context");
  EXPECT_EQ(j["variants"].size(), 2U);
  EXPECT_EQ(j["variants"][0]["context"].size(), 4U);
  EXPECT_TRUE(j["variants"][0].contains("adaptability"));
  const std::string md = summary_markdown(*e);
  EXPECT_NE(md.find("| instance-nn/invariant/5 |"), std::string::npos) << md;
  EXPECT_NE(md.find("adaptability"), std::string::npos);
  auto refused = write_report(*e, "/proc/orthoflow_cannot_write_here");
  ASSERT_FALSE(refused);
  EXPECT_EQ(refused.error().code, EvalError::Code::WRITE_FAILED);
  fs::remove_all(out);
}

}  // namespace
}  // namespace orthoflow::evaluation
