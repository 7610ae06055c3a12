// A perceptual memory of spin-image sets (kernels/spin_set.hpp, learning/spin_set_learner.hpp): its
// schema names the set's parameters, it reopens with the same answers, and a store of other
// parameters is refused naming both.
#include <gtest/gtest.h>

#include <bit>
#include <string>
#include <vector>

#include "learning/detail/memory_codec.hpp"
#include "learning/perceptual_memory.hpp"
#include "tests/learning/memory_test_util.hpp"

namespace orthoflow::learning {
namespace {

kernels::SpinSetParams small_set() {
  kernels::SpinSetParams p;
  p.features.spin.image_width = 1;  // 6 values an image
  p.max_keypoints = 4;              // 1 + 4 x 6 = 25 values
  return p;
}

// A set of category @p c: 1 + v % 4 images around c.
std::vector<float> set_view(std::size_t c, std::size_t v) {
  std::vector<float> out(small_set().length(), 0.0F);
  const std::size_t n = 1 + v % 4;
  out[0] = static_cast<float>(n);
  for (std::size_t i = 0; i < n * 6; ++i)
    out[1 + i] = static_cast<float>(c) + 0.1F * static_cast<float>((v * 7 + i * 3) % 5);
  return out;
}

TEST(SpinSetMemory, ReopensWithTheSameAnswersAndRefusesOtherParameters) {
  const auto dir = test::fresh_dir();
  MemoryConfig cfg = test::small_config(LearnerKind::INSTANCE);
  cfg.descriptor = kernels::DescriptorSpec::make_spin_set(small_set());
  const auto q = set_view(2, 11);
  Prediction before;
  {
    auto m = PerceptualMemory::open(dir, cfg);
    ASSERT_TRUE(m) << m.error().to_string();
    for (std::size_t c = 0; c < 3; ++c) {
      std::vector<ViewRecord> views;
      for (std::size_t v = 1; v <= 5; ++v)
        views.push_back(ViewRecord{set_view(c, v), {}, {}, 0, 0});
      ASSERT_TRUE(m->teach("c" + std::to_string(c), views));
    }
    EXPECT_STREQ(m->learner().kind(), "instance-spin-set");
    AskScratch scratch;
    m->learner().prepare(scratch);
    before = m->learner().ask(q, scratch);
    EXPECT_EQ(before.label.view(), "c2");
  }
  {
    auto again = PerceptualMemory::open(dir, cfg);
    ASSERT_TRUE(again) << again.error().to_string();
    AskScratch scratch;
    again->learner().prepare(scratch);
    const Prediction after = again->learner().ask(q, scratch);
    EXPECT_EQ(after.label, before.label);
    EXPECT_EQ(std::bit_cast<std::uint32_t>(after.score),
              std::bit_cast<std::uint32_t>(before.score));
    EXPECT_EQ(again->learner().stats().views, 15U);
  }
  MemoryConfig other = cfg;
  other.descriptor.spin_set.max_keypoints = 5;
  auto refused = PerceptualMemory::open(dir, other);
  ASSERT_FALSE(refused);
  EXPECT_EQ(refused.error().code, MemoryError::Code::PARAMS_MISMATCH);
  EXPECT_NE(refused.error().to_string().find("spin keypoints=4"), std::string::npos)
      << refused.error().to_string();
  EXPECT_NE(refused.error().to_string().find("spin keypoints=5"), std::string::npos);
}

TEST(SpinSetMemory, TheSchemaCarriesTheSetAndRefusesImpossibleOnes) {
  kernels::SpinSetParams p = small_set();
  p.features.keypoint_leaf = 0.04F;
  const auto spec = kernels::DescriptorSpec::make_spin_set(p);
  const std::string json = encode_schema(spec);
  std::uint32_t version = 0;
  std::string why;
  const auto back = decode_schema(json, version, why);
  ASSERT_TRUE(back) << why;
  EXPECT_EQ(*back, spec);
  EXPECT_EQ(back->describe(), spec.describe());
  auto replaced = [&](const std::string& from, const std::string& to) {
    std::string bad = json;
    bad.replace(bad.find(from), from.size(), to);
    return decode_schema(bad, version, why);
  };
  EXPECT_FALSE(replaced("\"max_keypoints\":4", "\"max_keypoints\":0"));
  EXPECT_FALSE(replaced("\"max_keypoints\":4", "\"max_keypoints\":4294967296"));
  EXPECT_FALSE(replaced("\"image_width\":1", "\"image_width\":17"));
  EXPECT_FALSE(replaced("\"support_angle_cos\":0.0", "\"support_angle_cos\":1e300"));
  EXPECT_NE(why.find("spin_set"), std::string::npos) << why;
  EXPECT_FALSE(replaced("\"spin_set\"", "\"other_set\""));
}

}  // namespace
}  // namespace orthoflow::learning
