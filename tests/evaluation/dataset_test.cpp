// Dataset scanning (layout rules and errors), describing views (parallel, perturbed, cached) and
// the descriptor cache (reuse, invalidation on a changed file, corrupt cache files ignored).
#include <gtest/gtest.h>

#include <fstream>

#include "evaluation/dataset.hpp"
#include "evaluation/derived_views.hpp"
#include "evaluation/descriptor_cache.hpp"
#include "evaluation/descriptors.hpp"
#include "tests/evaluation/box_dataset.hpp"

namespace orthoflow::evaluation {
namespace {

namespace fs = std::filesystem;

void touch(const fs::path& p, const std::string& text = "x") {
  fs::create_directories(p.parent_path());
  std::ofstream(p) << text;
}

TEST(Dataset, ScanIsSortedAndSkipsHiddenAndOtherFiles) {
  const fs::path root = testing::unique_dir("scan");
  testing::write_box_dataset(root, 3, 2, 2);
  touch(root / "README.md");
  touch(root / ".cache" / "x" / "y" / "z.pcd");
  touch(root / "box1" / "inst0" / "notes.txt");
  auto ds = scan_dataset(root);
  ASSERT_TRUE(ds) << ds.error().to_string();
  EXPECT_EQ(ds->categories, (std::vector<std::string>{"box0", "box1", "box2"}));
  EXPECT_EQ(ds->instances.size(), 6U);
  ASSERT_EQ(ds->views.size(), 12U);
  EXPECT_EQ(ds->views[0].relative, "box0/inst0/view0.pcd");
  EXPECT_EQ(ds->views[11].relative, "box2/inst1/view1.pcd");
  EXPECT_EQ(ds->views[5].category, 1U);
  EXPECT_EQ(ds->views_of(2).size(), 4U);
  fs::remove_all(root);
}

TEST(Dataset, LayoutErrorsNameTheProblem) {
  const fs::path root = testing::unique_dir("layout");
  const auto expect_error = [&](const std::string& needle) {
    auto ds = scan_dataset(root);
    ASSERT_FALSE(ds);
    EXPECT_EQ(ds.error().code, EvalError::Code::BAD_DATASET);
    EXPECT_NE(ds.error().message.find(needle), std::string::npos) << ds.error().message;
  };
  expect_error("holds no view");
  touch(root / "cup" / "a.pcd");
  expect_error("directly in a category folder");
  fs::remove_all(root / "cup");
  touch(root / "top.pcd");
  expect_error("at the top level");
  fs::remove(root / "top.pcd");
  fs::create_directories(root / "empty" / "inst");
  expect_error("'empty'");
  fs::remove_all(root / "empty");
  touch(root / std::string(70, 'n') / "i" / "v.pcd");
  expect_error("longer than 63 bytes");
  auto missing = scan_dataset(root / "nope");
  ASSERT_FALSE(missing);
  EXPECT_NE(missing.error().message.find("not a directory"), std::string::npos);
  fs::remove_all(root);
}

TEST(Descriptors, BadViewIsNamedAndBadSpecRefused) {
  const fs::path root = testing::unique_dir("badview");
  testing::write_box_dataset(root, 2, 1, 2);
  touch(root / "box1" / "inst0" / "view9.pcd", "not a pcd");
  auto ds = scan_dataset(root);
  ASSERT_TRUE(ds);
  auto t = describe_dataset(*ds, ViewDescription{}, {}, nullptr, nullptr, nullptr);
  ASSERT_FALSE(t);
  EXPECT_EQ(t.error().code, EvalError::Code::BAD_VIEW);
  EXPECT_NE(t.error().message.find("view9.pcd"), std::string::npos) << t.error().message;
  ViewDescription zero_bins;
  zero_bins.descriptor.good.bins = 0;
  EXPECT_EQ(describe_dataset(*ds, zero_bins, {}, nullptr, nullptr, nullptr).error().code,
            EvalError::Code::BAD_CONFIG);
  ViewDescription nan_noise;
  nan_noise.perturbation = Perturbation::NOISE;
  nan_noise.amount_m = std::nan("");
  EXPECT_EQ(describe_dataset(*ds, nan_noise, {}, nullptr, nullptr, nullptr).error().code,
            EvalError::Code::BAD_CONFIG);
  fs::remove_all(root);
}

TEST(Descriptors, CacheIsReusedAndInvalidatedByAChangedFile) {
  const fs::path root = testing::unique_dir("cache");
  const fs::path cache = root / ".descriptor_cache";
  testing::write_box_dataset(root, 2, 2, 3);
  auto ds = scan_dataset(root);
  ASSERT_TRUE(ds);
  DescribeStats first, second, third, fourth;
  ViewDescription spec;
  spec.descriptor.good.bins = 5;
  auto a = describe_dataset(*ds, spec, cache, nullptr, &first, nullptr);
  auto b = describe_dataset(*ds, spec, cache, nullptr, &second, nullptr);
  ASSERT_TRUE(a && b);
  EXPECT_EQ(first.computed, 12U);
  EXPECT_EQ(second.cached, 12U);
  EXPECT_EQ(a->values, b->values);
  // A rewritten file (other points, other size) is described again; the others still come from the
  // cache.
  kernels::PointCloud other = testing::box_view(1, 1, 1);
  other.resize_unorganized(300);
  ASSERT_TRUE(
      formats::write_pcd(other, root / "box0/inst0/view0.pcd", formats::PcdEncoding::BINARY));
  auto c = describe_dataset(*ds, spec, cache, nullptr, &third, nullptr);
  ASSERT_TRUE(c);
  EXPECT_EQ(third.computed, 1U);
  EXPECT_EQ(third.cached, 11U);
  EXPECT_NE(c->row(0)[0], a->row(0)[0]);
  // A corrupt cache file is ignored: everything is recomputed and the cache rewritten.
  for (const auto& e : fs::directory_iterator(cache)) {
    std::ofstream(e.path(), std::ios::trunc) << "OFDC garbage";
  }
  auto d = describe_dataset(*ds, spec, cache, nullptr, &fourth, nullptr);
  ASSERT_TRUE(d);
  EXPECT_EQ(fourth.computed, 12U);
  EXPECT_EQ(d->values, c->values);
  fs::remove_all(root);
}

TEST(Descriptors, PerturbationsAreDeterministicAndDoWhatTheySay) {
  const kernels::PointCloud cloud = testing::box_view(2, 0, 0);
  ViewDescription noise;
  noise.perturbation = Perturbation::NOISE;
  noise.amount_m = 0.005;
  noise.seed = 3;
  kernels::PointCloud n1, n2, n3;
  ASSERT_TRUE(perturb_view(cloud, noise, "a/b/c.pcd", n1));
  ASSERT_TRUE(perturb_view(cloud, noise, "a/b/c.pcd", n2));
  ASSERT_TRUE(perturb_view(cloud, noise, "a/b/d.pcd", n3));
  ASSERT_EQ(n1.size(), cloud.size());
  EXPECT_TRUE(std::equal(n1.x().begin(), n1.x().end(), n2.x().begin()));
  EXPECT_FALSE(std::equal(n1.x().begin(), n1.x().end(), n3.x().begin()));
  double sq = 0.0;
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    sq += (n1.x()[i] - cloud.x()[i]) * (n1.x()[i] - cloud.x()[i]);
  }
  EXPECT_NEAR(std::sqrt(sq / static_cast<double>(cloud.size())), 0.005, 0.001);
  ViewDescription voxel;
  voxel.perturbation = Perturbation::DOWNSAMPLE;
  voxel.amount_m = 0.02;
  kernels::PointCloud v;
  ASSERT_TRUE(perturb_view(cloud, voxel, "x", v));
  EXPECT_LT(v.size(), cloud.size() / 4);
  EXPECT_GT(v.size(), 4U);
  EXPECT_EQ(noise.key(), "good-invariant-15-noise-5000um-s3");
  EXPECT_EQ(voxel.key(), "good-invariant-15-voxel-20000um");
}

TEST(DescriptorCache, RoundTripAndMalformedBytesGiveAnEmptyCache) {
  DescriptorCache cache;
  cache.length = 3;
  cache.entries["a/b/c.pcd"] = DescriptorCache::Entry{FileStamp{10, 20}, {0.1F, 0.2F, 0.7F}};
  cache.entries["z/y/x.pcd"] = DescriptorCache::Entry{FileStamp{11, -5}, {1.0F, 0.0F, 0.0F}};
  const std::string bytes = encode_descriptor_cache(cache);
  const DescriptorCache back = parse_descriptor_cache(bytes, 3);
  ASSERT_EQ(back.entries.size(), 2U);
  EXPECT_EQ(back.entries.at("z/y/x.pcd").stamp, (FileStamp{11, -5}));
  EXPECT_EQ(back.entries.at("a/b/c.pcd").descriptor[2], 0.7F);
  EXPECT_TRUE(parse_descriptor_cache(bytes, 4).entries.empty());  // other descriptor length
  for (std::size_t cut = 0; cut < bytes.size(); ++cut) {
    EXPECT_TRUE(parse_descriptor_cache(std::string_view(bytes).substr(0, cut), 3).entries.empty())
        << cut;
  }
  std::string extra = bytes + "x";
  EXPECT_TRUE(parse_descriptor_cache(extra, 3).entries.empty());
  std::string huge_count = bytes;
  huge_count[16] = '\xff';
  EXPECT_TRUE(parse_descriptor_cache(huge_count, 3).entries.empty());
}

}  // namespace
}  // namespace orthoflow::evaluation

namespace orthoflow::evaluation {
namespace {

TEST(DerivedViews, CropsAreDeterministicPartialAndViewZeroIsTheWholeCloud) {
  const kernels::PointCloud cloud = testing::box_view(1, 0, 0);
  const kernels::PointCloud whole = derive_view(cloud, 0, 5);
  ASSERT_EQ(whole.size(), cloud.size());
  EXPECT_TRUE(std::equal(whole.x().begin(), whole.x().end(), cloud.x().begin()));
  for (std::uint32_t v = 1; v < 8; ++v) {
    const kernels::PointCloud a = derive_view(cloud, v, 5);
    const kernels::PointCloud b = derive_view(cloud, v, 5);
    EXPECT_GE(a.size(), cloud.size() * 7 / 10 - 1);
    EXPECT_LE(a.size(), cloud.size());
    ASSERT_EQ(a.size(), b.size());
    EXPECT_TRUE(std::equal(a.z().begin(), a.z().end(), b.z().begin()));
  }
  kernels::PointCloud nan_only;
  nan_only.resize_unorganized(3);
  for (std::size_t i = 0; i < 3; ++i) { nan_only.x()[i] = std::nanf(""); }
  EXPECT_TRUE(derive_view(nan_only, 2, 1).empty());
}

}  // namespace
}  // namespace orthoflow::evaluation
