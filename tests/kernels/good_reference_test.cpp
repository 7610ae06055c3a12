// The shared GOOD vectors (testdata/good): reference mode equals one of the 4 reference variants
// and invariant mode one of the 4 frame binnings, at 5 and 15 bins, for every cloud (L1 <= 0.01).
#include <algorithm>

#include "tests/kernels/good_test_util.hpp"

namespace {

using namespace good_test;

struct Case {
  std::string name;  // path stem relative to testdata/good, e.g. "box" or "timing/timing_5k"
  std::size_t bins;
};

std::vector<Case> all_cases() {
  std::vector<Case> cases;
  for (const char* sub : {"", "timing"}) {
    for (const auto& e : fs::directory_iterator(good_dir() / sub)) {
      if (e.path().extension() != ".pcd") { continue; }
      const std::string stem = (fs::path(sub) / e.path().stem()).string();
      for (const std::size_t bins : {5U, 15U}) { cases.push_back({stem, bins}); }
    }
  }
  std::sort(cases.begin(), cases.end(), [](const Case& a, const Case& b) {
    return a.name + std::to_string(a.bins) < b.name + std::to_string(b.bins);
  });
  return cases;
}

std::string case_name(const ::testing::TestParamInfo<Case>& info) {
  std::string n = info.param.name + "_bins" + std::to_string(info.param.bins);
  std::replace(n.begin(), n.end(), '/', '_');
  return n;
}

class GoodVectors : public ::testing::TestWithParam<Case> {
 protected:
  fs::path file(const std::string& ext) const {
    return good_dir() / (GetParam().name + ".bins" + std::to_string(GetParam().bins) + ext);
  }
};

TEST_P(GoodVectors, ReferenceModeMatchesAVariant) {
  if (!fs::exists(file(".variants"))) {
    GTEST_SKIP() << "no .variants file for " << GetParam().name;
  }
  const Cloud c = load(good_dir() / (GetParam().name + ".pcd"));
  ok::GoodConfig cfg{GetParam().bins, ok::GoodMode::REFERENCE, std::nullopt};
  const auto d = describe(c, cfg);
  const auto variants = load_variants(file(".variants"));
  ASSERT_EQ(variants.size(), 4U);
  EXPECT_LE(best_l1(d, variants), 0.01);
}

TEST_P(GoodVectors, InvariantModeMatchesAFrame) {
  const Cloud c = load(good_dir() / (GetParam().name + ".pcd"));
  const auto frames = load_variants(file(".frames"));
  ASSERT_EQ(frames.size(), 4U);
  const auto d =
      describe(c, ok::GoodConfig{GetParam().bins, ok::GoodMode::INVARIANT, std::nullopt});
  EXPECT_LE(best_l1(d, frames), 0.01);
}

INSTANTIATE_TEST_SUITE_P(Shared, GoodVectors, ::testing::ValuesIn(all_cases()), case_name);

}  // namespace
