// A view's spin images as one fixed-length set descriptor (kernels/spin_set.hpp): the layout, the
// images kept when there are more than the set holds, and what is not a set. Then the describer
// writes the set of a real view's features.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <vector>

#include "kernels/descriptor_spec.hpp"
#include "kernels/spin_set.hpp"

namespace orthoflow::kernels {
namespace {

// @p rows images of 2 values: image r is (r + 1, 0), or all zero (no weight) when r is in @p empty.
std::vector<float> images(std::size_t rows, std::vector<std::size_t> empty = {}) {
  std::vector<float> v(rows * 2, 0.0F);
  for (std::size_t r = 0; r < rows; ++r)
    if (std::find(empty.begin(), empty.end(), r) == empty.end()) v[2 * r] = float(r + 1);
  return v;
}

TEST(SpinSet, LayoutIsCountThenImagesThenZeros) {
  std::vector<float> out(1 + 4 * 2, -1.0F);
  EXPECT_EQ(write_spin_set(images(3, {1}), 2, 4, out), 2U) << "an image without weight is no image";
  EXPECT_EQ(out, (std::vector<float>{2, 1, 0, 3, 0, 0, 0, 0, 0}));
  EXPECT_EQ(spin_set_count(out, 2), 2U);
  EXPECT_EQ(write_spin_set(images(0), 2, 4, out), 0U);
  EXPECT_EQ(out, std::vector<float>(9, 0.0F));
  EXPECT_FALSE(spin_set_count(out, 2)) << "an empty set is not a set";
}

TEST(SpinSet, MoreImagesThanItHoldsKeepsThemEvenlySpaced) {
  // 10 images, 4 kept: images floor(i 10 / 4) = 0, 2, 5, 7.
  std::vector<float> out(1 + 4 * 2);
  EXPECT_EQ(write_spin_set(images(10), 2, 4, out), 4U);
  EXPECT_EQ(out, (std::vector<float>{4, 1, 0, 3, 0, 6, 0, 8, 0}));
  // Of the images with weight: with 0, 3 and 4 empty, the weighted are 1 2 5 6 7 8 9 (7 of them):
  // kept 0, 1, 3, 5 -> images 1, 2, 6, 8.
  EXPECT_EQ(write_spin_set(images(10, {0, 3, 4}), 2, 4, out), 4U);
  EXPECT_EQ(out, (std::vector<float>{4, 2, 0, 3, 0, 7, 0, 9, 0}));
  // Exactly as many as it holds: all, in order.
  EXPECT_EQ(write_spin_set(images(4), 2, 4, out), 4U);
  EXPECT_EQ(out, (std::vector<float>{4, 1, 0, 2, 0, 3, 0, 4, 0}));
}

TEST(SpinSet, WhatIsNotASetIsRefused) {
  std::vector<float> ok{2, 1, 0, 3, 0, 0, 0};
  EXPECT_EQ(spin_set_count(ok, 2), 2U);
  for (const float count : {0.0F, 4.0F, 1.5F, -1.0F, NAN, INFINITY}) {
    std::vector<float> v = ok;
    v[0] = count;
    EXPECT_FALSE(spin_set_count(v, 2)) << count;
  }
  std::vector<float> tail = ok;
  tail[6] = 1e-6F;  // after the last image
  EXPECT_FALSE(spin_set_count(tail, 2));
  std::vector<float> nan = ok;
  nan[3] = NAN;
  EXPECT_FALSE(spin_set_count(nan, 2));
  EXPECT_FALSE(spin_set_count(std::span<const float>(ok).first(6), 2)) << "not 1 + k x 2 values";
  EXPECT_FALSE(spin_set_count({}, 2));
  EXPECT_FALSE(spin_set_count(ok, 0));
}

TEST(SpinSet, TheSpecificationChecksItsParameters) {
  SpinSetParams p;
  EXPECT_TRUE(p.valid());
  EXPECT_EQ(p.length(), 1U + 128U * 153U) << "IW 8: 9 x 17 values an image";
  const DescriptorSpec spec = DescriptorSpec::make_spin_set(p);
  EXPECT_EQ(spec.describe(), "spin keypoints=128 iw=8 sl=0.1 sa=0 vs=0.04 nr=0.02");
  EXPECT_EQ(descriptor_kind("spin"), DescriptorKind::SPIN_SET);
  EXPECT_TRUE(spec.spin_features());
  EXPECT_FALSE(spec.local()) << "no dictionary";
  for (auto bad : {+[](SpinSetParams& s) { s.max_keypoints = 0; },
                   +[](SpinSetParams& s) { s.max_keypoints = MAX_SET_KEYPOINTS + 1; },
                   +[](SpinSetParams& s) { s.features.spin.image_width = 0; },
                   +[](SpinSetParams& s) { s.features.spin.support_length = NAN; },
                   +[](SpinSetParams& s) { s.features.keypoint_leaf = 0.0F; },
                   +[](SpinSetParams& s) { s.features.spin.support_angle_cos = 1.5F; }}) {
    SpinSetParams q;
    bad(q);
    EXPECT_FALSE(q.valid());
    EXPECT_FALSE(DescriptorSpec::make_spin_set(q).validate());
  }
  SpinSetParams other;
  other.max_keypoints = 64;
  EXPECT_FALSE(DescriptorSpec::make_spin_set(other) == spec);
  EXPECT_TRUE(DescriptorSpec::make_spin_set(p) == spec);
}

// A box's visible faces, 1 cm apart: the describer writes the set of their spin images.
TEST(SpinSet, TheDescriberWritesAViewsSet) {
  PointCloud cloud;
  cloud.resize_unorganized(2 * 12 * 12);
  std::size_t n = 0;
  for (int i = 0; i < 12; ++i)
    for (int j = 0; j < 12; ++j)
      for (const auto& [x, y, z] :
           {std::array<float, 3>{0.01F * float(i), 0.01F * float(j), 0.0F},
            std::array<float, 3>{0.01F * float(i), 0.0F, 0.01F * float(j + 1)}}) {
        cloud.x()[n] = x, cloud.y()[n] = y, cloud.z()[n] = z;
        ++n;
      }
  SpinSetParams p;
  p.max_keypoints = 64;
  p.features = SpinFeatureParams{};  // VS 1 cm: a keypoint every centimetre
  Describer describer(DescriptorSpec::make_spin_set(p));
  std::vector<float> out(p.length(), -1.0F);
  auto described = describer.describe(cloud.points(), out);
  ASSERT_TRUE(described) << to_string(described.error());
  const auto count = spin_set_count(out, p.image_values());
  ASSERT_TRUE(count);
  EXPECT_EQ(*count, describer.features());
  EXPECT_GT(*count, 16U);
  EXPECT_LE(*count, 64U);
  // Not enough room: refused, nothing half written past the end.
  std::vector<float> small(p.length() - 1);
  EXPECT_FALSE(describer.describe(cloud.points(), small));
}

}  // namespace
}  // namespace orthoflow::kernels
