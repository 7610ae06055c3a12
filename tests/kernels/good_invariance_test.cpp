// Invariant mode: 100 seeded random rigid motions of each asymmetric shared cloud and of each real
// object view give the same descriptor (L1 <= 0.01), and the reference mode does not (the flaw
// fixed).
#include "tests/kernels/good_test_util.hpp"

namespace {

using namespace good_test;

struct Case {
  std::string path;  // relative to ORTHOFLOW_SHARED_DIR
  std::size_t bins;
};

std::string case_name(const ::testing::TestParamInfo<Case>& info) {
  std::string n = fs::path(info.param.path).stem().string() + "_" +
                  fs::path(info.param.path).parent_path().filename().string() + "_bins" +
                  std::to_string(info.param.bins);
  return n;
}

class GoodInvariance : public ::testing::TestWithParam<Case> {};

TEST_P(GoodInvariance, HundredRigidMotionsGiveOneDescriptor) {
  const Cloud c = load(fs::path(ORTHOFLOW_SHARED_DIR) / GetParam().path);
  const ok::GoodConfig cfg{GetParam().bins, ok::GoodMode::INVARIANT, std::nullopt};
  ok::GoodResult base_info;
  const auto base = describe(c, cfg, &base_info);
  EXPECT_EQ(base_info.flags & ok::FRAME_UNRELIABLE, 0U) << "flags " << base_info.flags;
  std::mt19937 rng(1234U + static_cast<unsigned>(GetParam().bins));
  double worst = 0.0;
  for (int k = 0; k < 100; ++k) {
    const Cloud moved = random_motion(c, rng);
    worst = std::max(worst, l1(describe(moved, cfg), base));
  }
  EXPECT_LE(worst, 0.01);
  RecordProperty("worst_l1", std::to_string(worst));
}

INSTANTIATE_TEST_SUITE_P(
    Shapes, GoodInvariance,
    ::testing::Values(Case{"testdata/good/mug_handle.pcd", 5},
                      Case{"testdata/good/mug_handle.pcd", 15},
                      Case{"testdata/good/l_shape.pcd", 5}, Case{"testdata/good/l_shape.pcd", 15},
                      Case{"testdata/good/random_blob.pcd", 5},
                      Case{"testdata/good/random_blob.pcd", 15}, Case{"testdata/good/box.pcd", 15},
                      Case{"testdata/good/timing/timing_5k.pcd", 15},
                      Case{"data/objects/bottle.pcd", 5}, Case{"data/objects/bottle.pcd", 15},
                      Case{"data/objects/bowl.pcd", 5}, Case{"data/objects/bowl.pcd", 15},
                      Case{"data/objects/plate.pcd", 5}, Case{"data/objects/plate.pcd", 15},
                      Case{"data/objects/vase.pcd", 5}, Case{"data/objects/vase.pcd", 15}),
    case_name);

// The four poses of mug_handle in the vectors: the reference gives several descriptors, invariant
// mode one.
TEST(GoodInvariance, MugPosesAgreeInInvariantModeOnly) {
  const char* poses[] = {"mug_handle", "mug_handle_far", "mug_handle_rotA", "mug_handle_rotB"};
  for (const auto mode : {ok::GoodMode::INVARIANT, ok::GoodMode::REFERENCE}) {
    const ok::GoodConfig cfg{15, mode, std::nullopt};
    const auto first = describe(load(good_dir() / "mug_handle.pcd"), cfg);
    double worst = 0.0;
    for (const char* p : poses) {
      worst =
          std::max(worst, l1(describe(load(good_dir() / (std::string(p) + ".pcd")), cfg), first));
    }
    if (mode == ok::GoodMode::INVARIANT) {
      EXPECT_LE(worst, 0.01);
    } else {
      EXPECT_GE(worst, 0.2);  // distinct frames differ by 0.2 or more
    }
  }
}

}  // namespace
