// The bag of words' kernels: point_normals (kernels/point_normals.hpp) on surfaces whose normals
// are known, nearest_word against its scalar twin on random and adversarial inputs (ties, near
// ties, sizes around the lane counts, NaN), bag_of_words on a hand-made case, the dictionary id,
// and the Describer's BOW kind (kernels/descriptor_spec.hpp) on a seeded view.
#include <cmath>
#include <limits>
#include <memory>
#include <random>
#include <vector>

#include <gtest/gtest.h>

#include "kernels/descriptor_spec.hpp"
#include "kernels/point_normals.hpp"
#include "kernels/spin_features.hpp"
#include "kernels/visual_words.hpp"

namespace ok = orthoflow::kernels;

namespace {

constexpr float NAN_F = std::numeric_limits<float>::quiet_NaN();

struct Points {
  std::vector<float> x, y, z;
  void add(float a, float b, float c) {
    x.push_back(a);
    y.push_back(b);
    z.push_back(c);
  }
  [[nodiscard]] ok::PointsView view() const { return {x, y, z}; }
};

struct Normals {
  explicit Normals(std::size_t n) : x(n, 7.0F), y(n, 7.0F), z(n, 7.0F) {}
  std::vector<float> x, y, z;
  [[nodiscard]] ok::PointsSpan span() { return {x, y, z}; }
};

// A tilted plane z = 0.8 + 0.5 x seen from the origin, 2 mm grid.
Points tilted_plane() {
  Points p;
  for (int i = -20; i <= 20; ++i)
    for (int j = -20; j <= 20; ++j) {
      const float x = 0.002F * static_cast<float>(i), y = 0.002F * static_cast<float>(j);
      p.add(x, y, 0.8F + 0.5F * x);
    }
  return p;
}

// The near half of a sphere of radius 5 cm centred at (0, 0, 1), seeded.
Points half_sphere(std::uint32_t seed, std::size_t n) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> u(0.0F, 1.0F);
  Points p;
  for (std::size_t i = 0; i < n; ++i) {
    const float phi = 6.2832F * u(rng), c = -u(rng);  // z below the centre: facing the origin
    const float s = std::sqrt(1.0F - c * c);
    p.add(0.05F * s * std::cos(phi), 0.05F * s * std::sin(phi), 1.0F + 0.05F * c);
  }
  return p;
}

}  // namespace

TEST(PointNormals, APlaneGivesItsNormalFacingTheViewpoint) {
  const Points p = tilted_plane();
  Normals n(p.x.size());
  const std::vector<std::uint32_t> at{0, 400, 840, 1680};
  auto r = ok::point_normals(p.view(), at, {}, n.span());
  ASSERT_TRUE(r);
  EXPECT_EQ(r.value(), at.size());
  const float len = std::sqrt(1.25F);
  for (const std::uint32_t i : at) {  // (-0.5, 0, 1) / |.|, flipped towards the origin: z < 0
    EXPECT_NEAR(n.x[i], 0.5F / len, 1e-5F) << i;
    EXPECT_NEAR(n.y[i], 0.0F, 1e-5F) << i;
    EXPECT_NEAR(n.z[i], -1.0F / len, 1e-5F) << i;
  }
  EXPECT_EQ(n.x[1], 7.0F);  // a point not asked for is left as it was
}

TEST(PointNormals, ASphereGivesRadialNormals) {
  const Points p = half_sphere(3, 4000);
  Normals n(p.x.size());
  std::vector<std::uint32_t> at;
  for (std::uint32_t i = 0; i < 4000; i += 97) at.push_back(i);
  ok::PointNormalParams params;
  params.radius = 0.01F;
  ASSERT_TRUE(ok::point_normals(p.view(), at, params, n.span()));
  for (const std::uint32_t i : at) {
    if (p.z[i] > 0.995F) continue;  // near the rim the neighbourhood is one-sided
    const float rx = p.x[i] / 0.05F, ry = p.y[i] / 0.05F, rz = (p.z[i] - 1.0F) / 0.05F;
    EXPECT_GT(n.x[i] * rx + n.y[i] * ry + n.z[i] * rz, 0.99F) << i;  // outwards: to the viewer
  }
}

TEST(PointNormals, TooFewNeighboursOrABadPointGiveNaN) {
  Points p;
  p.add(0, 0, 1);
  p.add(0.001F, 0, 1);
  p.add(1, 1, 1);  // far from the others
  p.add(NAN_F, 0, 1);
  Normals n(p.x.size());
  const std::vector<std::uint32_t> at{0, 2, 3};
  auto r = ok::point_normals(p.view(), at, {}, n.span());
  ASSERT_TRUE(r);
  EXPECT_EQ(r.value(), 0U);
  for (const std::uint32_t i : at) EXPECT_TRUE(std::isnan(n.x[i])) << i;
}

TEST(PointNormals, RefusesBadParametersAndWritesNothing) {
  const Points p = tilted_plane();
  Normals n(p.x.size());
  ok::PointNormalParams bad;
  bad.radius = -1.0F;
  const std::vector<std::uint32_t> at{0};
  auto r = ok::point_normals(p.view(), at, bad, n.span());
  ASSERT_FALSE(r);
  EXPECT_NE(r.error().to_string().find("radius"), std::string::npos);
  const std::vector<std::uint32_t> past{static_cast<std::uint32_t>(p.x.size())};
  r = ok::point_normals(p.view(), past, {}, n.span());
  ASSERT_FALSE(r);
  EXPECT_EQ(r.error().code, ok::PointNormalError::Code::BAD_INDEX);
  Normals small(3);
  EXPECT_FALSE(ok::point_normals(p.view(), at, {}, small.span()));
  EXPECT_EQ(n.x[0], 7.0F);
  // Empty: nothing asked, nothing written.
  auto empty = ok::point_normals(p.view(), {}, {}, n.span());
  ASSERT_TRUE(empty);
  EXPECT_EQ(empty.value(), 0U);
}

namespace {

// words x dims structure-of-arrays with values from @p draw.
template <class Draw>
std::vector<float> make_words(std::size_t words, std::size_t dims, Draw draw) {
  std::vector<float> w(words * dims);
  for (float& v : w) v = draw();
  return w;
}

}  // namespace

TEST(NearestWord, EqualsTheTwinOnRandomAndAdversarialInputs) {
  std::mt19937 rng(5);
  std::uniform_real_distribution<float> u(0.0F, 1.0F);
  for (const std::size_t dims : {1U, 3U, 4U, 7U, 8U, 9U, 15U, 16U, 17U, 45U}) {
    for (const std::size_t words : {1U, 2U, 3U, 4U, 5U, 7U, 8U, 9U, 15U, 16U, 17U, 31U, 33U, 70U}) {
      auto w = make_words(words, dims, [&] { return u(rng); });
      const ok::DescriptorMatrixView view{w, dims, words, words};
      std::vector<float> scratch(words);
      for (int t = 0; t < 20; ++t) {
        std::vector<float> f(dims);
        for (float& v : f) v = u(rng);
        if (t % 4 == 1) {  // exactly a word: distance 0
          for (std::size_t d = 0; d < dims; ++d) f[d] = w[d * words + (t % words)];
        }
        if (t % 4 == 2 && words > 1) {  // two equal words: the tie goes to the lower index
          for (std::size_t d = 0; d < dims; ++d) w[d * words + words - 1] = w[d * words];
          for (std::size_t d = 0; d < dims; ++d) f[d] = w[d * words] + 1e-3F;
        }
        if (t % 4 == 3 && words > 1) {  // a near tie: the second word nudged by one ulp
          for (std::size_t d = 0; d < dims; ++d)
            w[d * words + 1] = std::nextafter(w[d * words], 2.0F);
          for (std::size_t d = 0; d < dims; ++d) f[d] = w[d * words] + 0.25F;
        }
        const std::size_t twin = ok::nearest_word_scalar(f, view);
        EXPECT_EQ(ok::nearest_word(f, view, scratch), twin)
            << "dims " << dims << " words " << words << " t " << t;
        if (t % 4 == 2 && words > 2) {  // never the later of the two equal words
          EXPECT_NE(twin, words - 1);
        }
      }
    }
  }
}

TEST(NearestWord, NoWordForANonFiniteFeatureOrAnEmptyDictionary) {
  std::vector<float> w{0.0F, 1.0F, 0.0F, 1.0F};  // 2 words of 2 values
  const ok::DescriptorMatrixView view{w, 2, 2, 2};
  std::vector<float> scratch(2);
  const std::vector<float> nan_feature{NAN_F, 0.0F};
  EXPECT_EQ(ok::nearest_word(nan_feature, view, scratch), ok::NO_WORD);
  EXPECT_EQ(ok::nearest_word_scalar(nan_feature, view), ok::NO_WORD);
  const std::vector<float> inf_feature{std::numeric_limits<float>::infinity(), 0.0F};
  EXPECT_EQ(ok::nearest_word(inf_feature, view, scratch), ok::NO_WORD);
  const ok::DescriptorMatrixView empty{{}, 2, 0, 0};
  const std::vector<float> f{0.0F, 0.0F};
  EXPECT_EQ(ok::nearest_word(f, empty, scratch), ok::NO_WORD);
  EXPECT_EQ(ok::nearest_word_scalar(f, empty), ok::NO_WORD);
}

TEST(BagOfWords, CountsEachFeatureOnceAndSkipsEmptyImages) {
  // Words (0, 0) and (1, 1); features near word 1, near word 0, near word 1, and an empty image.
  const std::vector<float> w{0.0F, 1.0F, 0.0F, 1.0F};
  const ok::DescriptorMatrixView view{w, 2, 2, 2};
  const std::vector<float> features{0.9F, 0.8F, 0.1F, 0.2F, 1.0F, 1.2F, 0.0F, 0.0F};
  std::vector<float> scratch(2), histogram(2, -1.0F);
  EXPECT_EQ(ok::bag_of_words(features, view, scratch, histogram), 3U);
  EXPECT_FLOAT_EQ(histogram[0], 1.0F / 3.0F);
  EXPECT_FLOAT_EQ(histogram[1], 2.0F / 3.0F);
  EXPECT_EQ(ok::bag_of_words({}, view, scratch, histogram), 0U);
  EXPECT_EQ(histogram[0], 0.0F);
  EXPECT_EQ(histogram[1], 0.0F);
}

namespace {

std::shared_ptr<ok::VisualDictionary> random_dictionary(std::size_t words, std::uint32_t seed) {
  auto d = std::make_shared<ok::VisualDictionary>();
  d->words = words;
  d->dims = ok::spin_image_bins(4);
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> u(0.0F, 0.05F);
  d->data = make_words(words, d->dims, [&] { return u(rng); });
  d->id = ok::dictionary_id(*d);
  return d;
}

}  // namespace

TEST(VisualDictionary, TheIdNamesTheWordsAndParameters) {
  auto a = random_dictionary(10, 1);
  EXPECT_EQ(a->id, ok::dictionary_id(*a));  // stable
  auto b = std::make_shared<ok::VisualDictionary>(*a);
  b->data[17] = std::nextafter(b->data[17], 1.0F);
  EXPECT_NE(ok::dictionary_id(*b), a->id);
  auto c = std::make_shared<ok::VisualDictionary>(*a);
  c->normal_radius = 0.03F;
  EXPECT_NE(ok::dictionary_id(*c), a->id);
  c->provenance = "something else";  // not part of the id
  c->normal_radius = a->normal_radius;
  EXPECT_EQ(ok::dictionary_id(*c), a->id);
  EXPECT_EQ(ok::dictionary_id_hex(0x3f2a9c0d11e4b7a0ULL), "3f2a9c0d11e4b7a0");
}

TEST(BowSpec, LengthDescriptionEqualityAndValidation) {
  auto d = random_dictionary(12, 2);
  const ok::DescriptorSpec spec = ok::DescriptorSpec::make_bow(d);
  EXPECT_EQ(spec.kind, ok::DescriptorKind::BOW);
  EXPECT_EQ(spec.length(), 12U);
  EXPECT_TRUE(spec.validate());
  EXPECT_EQ(spec.describe(),
            "bow words=12 iw=4 sl=0.05 vs=0.01 nr=0.02 dictionary=" + ok::dictionary_id_hex(d->id));
  EXPECT_EQ(spec, ok::DescriptorSpec::make_bow(std::make_shared<ok::VisualDictionary>(*d)));
  EXPECT_FALSE(spec == ok::DescriptorSpec::make_bow(random_dictionary(12, 3)));
  EXPECT_FALSE(spec == ok::DescriptorSpec{});
  EXPECT_FALSE(ok::DescriptorSpec::make_bow(nullptr).validate());
  auto wrong = std::make_shared<ok::VisualDictionary>(*d);
  wrong->dims = 10;
  const auto r = ok::DescriptorSpec::make_bow(wrong).validate();
  ASSERT_FALSE(r);
  EXPECT_NE(r.error().find("do not fit"), std::string::npos) << r.error();
}

TEST(BowDescriber, DescribesAViewAsTheSharesOfItsWords) {
  const Points p = half_sphere(9, 3000);
  auto d = random_dictionary(20, 4);
  // Words from the view's own features, so that they are used: every fifth image.
  ok::SpinFeatures features;
  auto k = features.compute(p.view(), {});
  ASSERT_TRUE(k);
  ASSERT_GT(features.described(), 20U);
  const auto images = features.images();
  for (std::size_t j = 0; j < d->words; ++j)
    for (std::size_t v = 0; v < d->dims; ++v)
      d->data[v * d->words + j] = images[(5 * j) * d->dims + v];
  d->id = ok::dictionary_id(*d);
  ok::Describer describer(ok::DescriptorSpec::make_bow(d));
  std::vector<float> out(d->words, -1.0F);
  auto info = describer.describe(p.view(), out);
  ASSERT_TRUE(info) << ok::to_string(info.error());
  EXPECT_EQ(info->length, d->words);
  EXPECT_EQ(describer.features(), features.described());
  double sum = 0.0;
  std::size_t used = 0;
  for (const float v : out) {
    EXPECT_GE(v, 0.0F);
    sum += v;
    used += v > 0.0F ? 1 : 0;
  }
  EXPECT_NEAR(sum, 1.0, 1e-5);
  EXPECT_GE(used, 5U);
  // The frame and box come from GOOD: the box of a 10 cm half sphere.
  EXPECT_NEAR(std::max({info->bbox[0], info->bbox[1], info->bbox[2]}), 0.1F, 0.01F);
  // Described twice: the same values.
  std::vector<float> again(d->words);
  ASSERT_TRUE(describer.describe(p.view(), again));
  EXPECT_EQ(out, again);
}

TEST(BowDescriber, AViewWithoutFeaturesIsRefusedWithTheReason) {
  auto d = random_dictionary(5, 6);
  ok::Describer describer(ok::DescriptorSpec::make_bow(d));
  Points sparse;  // three points a metre apart: no neighbour within the support
  sparse.add(0, 0, 1);
  sparse.add(1, 0, 1);
  sparse.add(0, 1, 1);
  std::vector<float> out(5);
  auto info = describer.describe(sparse.view(), out);
  ASSERT_FALSE(info);
  EXPECT_EQ(info.error(), ok::GoodError::NO_FEATURES);
  Points empty;
  EXPECT_FALSE(describer.describe(empty.view(), out));
}
