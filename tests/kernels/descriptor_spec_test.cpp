// The descriptor specification (kernels/descriptor_spec.hpp): length, equality, validation,
// description, and that Describer gives what compute_good gives for the same parameters.
#include "kernels/descriptor_spec.hpp"

#include <gtest/gtest.h>

#include <vector>

#include "core/rng.hpp"

namespace orthoflow::kernels {
namespace {

TEST(DescriptorSpec, LengthComesFromTheKindAndItsParameters) {
  EXPECT_EQ(DescriptorSpec{}.length(), 3U * 15U * 15U);  // thesis default: GOOD, 15 bins
  EXPECT_EQ(DescriptorSpec::make_good(5).length(), 75U);
  EXPECT_EQ(DescriptorSpec::make_good(1).length(), 3U);
  EXPECT_TRUE(DescriptorSpec{}.histogram());
}

TEST(DescriptorSpec, EqualityUsesTheEffectiveThreshold) {
  DescriptorSpec a = DescriptorSpec::make_good(15);
  DescriptorSpec b = a;
  b.good.threshold = GOOD_INVARIANT_THRESHOLD;  // explicitly the default: the same specification
  EXPECT_EQ(a, b);
  b.good.threshold = 0.02F;
  EXPECT_FALSE(a == b);
  EXPECT_FALSE(a == DescriptorSpec::make_good(15, GoodMode::REFERENCE));
  EXPECT_FALSE(a == DescriptorSpec::make_good(5));
}

TEST(DescriptorSpec, DescribeNamesKindAndParameters) {
  EXPECT_EQ(DescriptorSpec::make_good(5, GoodMode::REFERENCE).describe(),
            "good bins=5 mode=reference threshold=0.0015");
  EXPECT_EQ(DescriptorSpec{}.describe(), "good bins=15 mode=invariant threshold=0.015");
}

TEST(DescriptorSpec, ValidateRefusesBadParameters) {
  EXPECT_TRUE(DescriptorSpec{}.validate());
  EXPECT_FALSE(DescriptorSpec::make_good(0).validate());
  EXPECT_FALSE(DescriptorSpec::make_good(GOOD_MAX_BINS + 1).validate());
  DescriptorSpec negative;
  negative.good.threshold = -1.0F;
  const auto r = negative.validate();
  ASSERT_FALSE(r);
  EXPECT_NE(r.error().find("threshold"), std::string::npos) << r.error();
}

TEST(Describer, EqualsComputeGoodWithTheSameParameters) {
  core::Rng rng(11);
  std::vector<float> x(500), y(500), z(500);
  for (std::size_t i = 0; i < x.size(); ++i) {
    x[i] = static_cast<float>(0.1 * rng.uniform());
    y[i] = static_cast<float>(0.05 * rng.uniform());
    z[i] = static_cast<float>(0.02 * rng.uniform() + 0.7);
  }
  const DescriptorSpec spec = DescriptorSpec::make_good(7);
  Describer describer(spec);
  std::vector<float> ours(spec.length()), theirs(spec.length());
  auto info = describer.describe({x, y, z}, ours);
  GoodScratch scratch(7);
  auto good = compute_good({x, y, z}, spec.good, scratch, theirs);
  ASSERT_TRUE(info && good);
  EXPECT_EQ(info->length, spec.length());
  EXPECT_EQ(info->frame, good->frame);
  EXPECT_EQ(ours, theirs);
  std::vector<float> none;
  EXPECT_EQ(describer.describe({none, none, none}, ours).error(), GoodError::EMPTY_CLOUD);
}

}  // namespace
}  // namespace orthoflow::kernels
