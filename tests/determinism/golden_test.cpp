// Cross-architecture determinism: recomputes the golden sections (golden_outputs.hpp) on this build
// and compares them with tests/golden/determinism.json, produced on x86-64. CTest runs this
// natively and, in the aarch64 preset, under qemu: the same file must pass on both.
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <string>

#include "golden_outputs.hpp"
#include "kernels/simd_arch.hpp"

namespace {

using nlohmann::json;
namespace ot = orthoflow::testing;

const json& golden() {
  static const json file = [] {
    std::ifstream in(std::string(ORTHOFLOW_SOURCE_DIR) + "/tests/golden/determinism.json");
    return in ? json::parse(in) : json();
  }();
  return file;
}

class Determinism : public ::testing::Test {
 protected:
  void SetUp() override {
    ASSERT_TRUE(golden().is_object()) << "tests/golden/determinism.json missing or unreadable";
    std::printf("golden from %s, running on %s\n", golden().value("generated_on", "?").c_str(),
                orthoflow::kernels::simd_arch_name());
  }
};

TEST_F(Determinism, SyntheticScenesAreBitIdentical) {
  const json actual = ot::golden_scenes();
  ASSERT_EQ(actual.size(), golden()["scenes"].size());
  for (const auto& [seed, expected] : golden()["scenes"].items()) {
    ASSERT_TRUE(actual.contains(seed)) << "scene " << seed;
    for (const auto& [field, value] : expected.items()) {
      EXPECT_EQ(actual[seed][field], value) << "scene seed " << seed << " field " << field;
    }
  }
}

TEST_F(Determinism, SegmentationChainAgreesWithinTolerance) {
  const json actual = ot::golden_segmentation();
  for (const auto& [seed, expected] : golden()["segmentation"].items()) {
    const json& got = actual.at(seed);
    for (std::size_t k = 0; k < 3; ++k) {
      EXPECT_NEAR(got["normal"][k].get<double>(), expected["normal"][k].get<double>(),
                  ot::GOLDEN_PLANE_TOL)
          << "scene " << seed << " normal[" << k << "]";
    }
    EXPECT_NEAR(got["d"].get<double>(), expected["d"].get<double>(), ot::GOLDEN_PLANE_TOL)
        << "scene " << seed;
    const double inliers = expected["inliers"].get<double>();
    EXPECT_NEAR(got["inliers"].get<double>(), inliers, inliers * ot::GOLDEN_INLIER_REL_TOL)
        << "scene " << seed;
    const json& sizes = expected["cluster_sizes"];
    ASSERT_EQ(got["cluster_sizes"].size(), sizes.size()) << "scene " << seed << ": object count";
    for (std::size_t c = 0; c < sizes.size(); ++c) {
      EXPECT_LE(std::labs(got["cluster_sizes"][c].get<long>() - sizes[c].get<long>()),
                ot::GOLDEN_CLUSTER_POINTS_TOL)
          << "scene " << seed << " cluster " << c;
    }
  }
}

TEST_F(Determinism, GoodDescriptorsAgreeWithinL1Tolerance) {
  const json actual = ot::golden_good(ORTHOFLOW_SHARED_DIR);
  ASSERT_EQ(actual.size(), golden()["good"].size());
  for (const auto& [name, expected] : golden()["good"].items()) {
    const json& got = actual.at(name);
    EXPECT_EQ(got["points_used"], expected["points_used"]) << name;
    EXPECT_EQ(got["signs"], expected["signs"]) << name;
    const json& e = expected["descriptor"];
    ASSERT_EQ(got["descriptor"].size(), e.size()) << name;
    double l1 = 0.0;
    for (std::size_t i = 0; i < e.size(); ++i) {
      l1 += std::fabs(got["descriptor"][i].get<double>() - e[i].get<double>());
    }
    std::printf("GOOD %s: L1 %.3g\n", name.c_str(), l1);
    EXPECT_LE(l1, ot::GOLDEN_GOOD_L1_TOL) << name;
  }
}

TEST_F(Determinism, LearnerDecisionsAreTheSame) {
  const json actual = ot::golden_learning();
  ASSERT_EQ(actual.size(), golden()["learning"].size());
  for (const auto& [kind, steps] : golden()["learning"].items()) {
    ASSERT_EQ(actual.at(kind).size(), steps.size()) << kind;
    for (std::size_t s = 0; s < steps.size(); ++s) {
      const json& expected = steps[s]["answers"];
      const json& got = actual[kind][s]["answers"];
      ASSERT_EQ(got.size(), expected.size());
      for (std::size_t a = 0; a < expected.size(); ++a) {
        const std::string where = kind + " after teaching " +
                                  steps[s]["taught"].get<std::string>() + ", view " +
                                  std::to_string(a);
        EXPECT_EQ(got[a]["label"], expected[a]["label"]) << where;
        EXPECT_EQ(got[a]["unknown"], expected[a]["unknown"]) << where;
        EXPECT_EQ(got[a]["runner_up"], expected[a]["runner_up"]) << where;
        for (const char* key : {"score", "runner_up_score"}) {
          if (expected[a][key].is_null()) {  // not finite on the reference machine
            EXPECT_TRUE(got[a][key].is_null()) << where << " " << key;
            continue;
          }
          const double e = expected[a][key].get<double>();
          EXPECT_NEAR(got[a][key].get<double>(), e, std::fabs(e) * ot::GOLDEN_SCORE_REL_TOL)
              << where << " " << key;
        }
      }
    }
  }
}

}  // namespace
