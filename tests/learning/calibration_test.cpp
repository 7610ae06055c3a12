// Leave-one-out CT calibration (learning/calibration.hpp) on separable and overlapping categories.
#include <gtest/gtest.h>

#include <vector>

#include "learning/calibration.hpp"

namespace orthoflow::learning {
namespace {

// Category at (cx, 0): views (cx + 0.1 i, 0.05 i) for i < n.
std::vector<float> cluster(float cx, int n) {
  std::vector<float> v;
  for (int i = 0; i < n; ++i) {
    v.push_back(cx + 0.1F * static_cast<float>(i));
    v.push_back(0.05F * static_cast<float>(i));
  }
  return v;
}

TEST(Calibration, SeparatedCategoriesGiveAThresholdBetweenKnownAndUnknown) {
  const auto a = cluster(0.0F, 4);
  const auto b = cluster(10.0F, 5);
  const auto c = cluster(-7.0F, 3);
  const std::vector<RestoredCategory> cats{
      {0, "a", {a, 2}, {}, 4}, {1, "b", {b, 2}, {}, 5}, {2, "c", {c, 2}, {}, 3}};
  for (const NocdApproach approach : {NocdApproach::MIN_DISTANCE, NocdApproach::MEAN_DISTANCE}) {
    InstanceConfig cfg;
    cfg.descriptor_length = 2;
    cfg.approach = approach;
    const auto result = calibrate_threshold(cats, cfg);
    ASSERT_TRUE(result);
    EXPECT_FLOAT_EQ(result->balanced_accuracy, 1.0F);
    EXPECT_EQ(result->known_samples, 12U);
    EXPECT_EQ(result->unknown_samples, 12U);
    // Approach I: a held-out view is one step (0.1118) from its neighbour and ICD is about 2 steps:
    // NOCD < 1; the nearest other category is 7 units away: NOCD > 20.
    EXPECT_GT(result->threshold, 0.5F);
    EXPECT_LT(result->threshold, 20.0F);
  }
}

TEST(Calibration, OverlappingCategoriesCannotBeSeparatedPerfectly) {
  const auto a = cluster(0.0F, 4);
  const auto b = cluster(0.15F, 4);  // interleaved with a
  const std::vector<RestoredCategory> cats{{0, "a", {a, 2}, {}, 4}, {1, "b", {b, 2}, {}, 4}};
  InstanceConfig cfg;
  cfg.descriptor_length = 2;
  const auto result = calibrate_threshold(cats, cfg);
  ASSERT_TRUE(result);
  EXPECT_LT(result->balanced_accuracy, 1.0F);
  EXPECT_GE(result->balanced_accuracy, 0.5F);
}

TEST(Calibration, ErrorsNameWhatIsMissing) {
  const auto a = cluster(0.0F, 3);
  const auto one = cluster(5.0F, 1);
  InstanceConfig cfg;
  cfg.descriptor_length = 2;
  const std::vector<RestoredCategory> single{{0, "a", {a, 2}, {}, 3}};
  EXPECT_EQ(calibrate_threshold(single, cfg).error(), CalibrationError::TOO_FEW_CATEGORIES);
  const std::vector<RestoredCategory> singletons{{0, "a", {one, 2}, {}, 1},
                                                 {1, "b", {one, 2}, {}, 1}};
  EXPECT_EQ(calibrate_threshold(singletons, cfg).error(), CalibrationError::TOO_FEW_VIEWS);
  EXPECT_STRNE(to_string(CalibrationError::TOO_FEW_VIEWS),
               to_string(CalibrationError::TOO_FEW_CATEGORIES));
}

}  // namespace
}  // namespace orthoflow::learning
