// Euclidean clustering against an O(n^2) union-find reference, the organized variant on a synthetic
// range image, every error code, and per-cluster statistics on known shapes.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <random>
#include <vector>

#include "kernels/cluster_stats.hpp"
#include "kernels/euclidean_cluster.hpp"

namespace ok = orthoflow::kernels;

namespace {

struct Cloud {
  std::vector<float> x, y, z;
  ok::PointsView view() const { return {x, y, z}; }
  void add(float a, float b, float c) { x.push_back(a), y.push_back(b), z.push_back(c); }
};

/// Brute force: components of the graph "within tol", sizes filtered, ids by lowest index.
std::vector<std::int32_t> reference(const Cloud& c, const ok::ClusterParams& p) {
  const std::size_t n = c.x.size();
  std::vector<std::size_t> parent(n);
  std::iota(parent.begin(), parent.end(), 0U);
  auto find = [&](std::size_t i) {
    while (parent[i] != i) { i = parent[i]; }
    return i;
  };
  auto ok_pt = [&](std::size_t i) {
    return std::isfinite(c.x[i]) && std::isfinite(c.y[i]) && std::isfinite(c.z[i]);
  };
  for (std::size_t i = 0; i < n; ++i) {
    for (std::size_t j = i + 1; j < n && ok_pt(i); ++j) {
      const float dx = c.x[i] - c.x[j], dy = c.y[i] - c.y[j], dz = c.z[i] - c.z[j];
      if (ok_pt(j) && dx * dx + dy * dy + dz * dz <= p.tolerance * p.tolerance) {
        const std::size_t a = find(i), b = find(j);
        parent[std::max(a, b)] = std::min(a, b);
      }
    }
  }
  std::vector<std::size_t> size(n, 0);
  for (std::size_t i = 0; i < n; ++i) { size[find(i)] += ok_pt(i) ? 1U : 0U; }
  std::vector<std::int32_t> label(n, -1), id(n, -2);
  std::int32_t next = 0;
  for (std::size_t i = 0; i < n; ++i) {
    if (!ok_pt(i)) { continue; }
    const std::size_t r = find(i);
    if (id[r] == -2) { id[r] = (size[r] >= p.min_size && size[r] <= p.max_size) ? next++ : -1; }
    label[i] = id[r];
  }
  return label;
}

Cloud blobs(std::size_t per_blob, std::size_t blobs_n, float spread, std::uint32_t seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<float> g(0.0F, spread);
  std::uniform_real_distribution<float> centre(-1.0F, 1.0F);
  Cloud c;
  for (std::size_t b = 0; b < blobs_n; ++b) {
    const float cx = centre(rng), cy = centre(rng), cz = centre(rng);
    for (std::size_t i = 0; i < per_blob; ++i) { c.add(cx + g(rng), cy + g(rng), cz + g(rng)); }
  }
  // Interleave blobs so that ids do not follow blob order trivially.
  std::shuffle(c.x.begin(), c.x.end(), std::mt19937(seed)),
      std::shuffle(c.y.begin(), c.y.end(), std::mt19937(seed)),
      std::shuffle(c.z.begin(), c.z.end(), std::mt19937(seed));
  return c;
}

void expect_reference(const Cloud& c, const ok::ClusterParams& p) {
  ok::ClusterScratch scratch(c.x.size());
  std::vector<std::int32_t> labels(c.x.size());
  auto r = ok::euclidean_cluster(c.view(), {}, p, scratch, labels);
  ASSERT_TRUE(r) << r.error().to_string();
  const auto ref = reference(c, p);
  EXPECT_EQ(labels, ref);
  std::int32_t top = -1;
  for (const std::int32_t l : ref) { top = std::max(top, l); }
  EXPECT_EQ(*r, static_cast<std::size_t>(top + 1));
}

TEST(SegCluster, GridMatchesBruteForce) {
  ok::ClusterParams p;
  p.min_size = 5;
  for (const std::size_t n : {1U, 7U, 40U, 300U}) {
    expect_reference(blobs(n, 6, 0.03F, std::uint32_t(n)), p);
  }
  p.tolerance = 0.005F;
  p.min_size = 1;
  p.max_size = 50;
  expect_reference(blobs(200, 4, 0.02F, 5), p);
}

TEST(SegCluster, AdversarialInputs) {
  ok::ClusterParams p;
  p.min_size = 1;
  expect_reference(Cloud{}, p);
  Cloud nan_cloud;
  for (int i = 0; i < 20; ++i) { nan_cloud.add(std::numeric_limits<float>::quiet_NaN(), 0, 0); }
  expect_reference(nan_cloud, p);
  Cloud dup;
  for (int i = 0; i < 33; ++i) { dup.add(0.5F, 0.5F, 0.5F); }
  expect_reference(dup, p);
  Cloud huge;
  for (int i = 0; i < 17; ++i) {
    huge.add(1e6F + 0.01F * float(i), -1e6F, 3e5F);
  }  // a chain 1 cm apart
  expect_reference(huge, p);
}

TEST(SegCluster, OrganizedSeparatesByDepthAndMask) {
  // 40 x 30 range image: left half a wall at 1 m, right half one at 1.2 m, one masked-out column.
  const std::uint32_t w = 40, h = 30;
  Cloud c;
  for (std::uint32_t v = 0; v < h; ++v) {
    for (std::uint32_t u = 0; u < w; ++u) {
      const float z = u < 20 ? 1.0F : 1.2F;
      c.add((float(u) - 20.0F) * 0.002F * z, (float(v) - 15.0F) * 0.002F * z, z);
    }
  }
  std::vector<std::uint8_t> mask(c.x.size(), 1);
  for (std::uint32_t v = 0; v < h; ++v) {
    mask[v * w + 30] = 0;
  }  // one pixel gap: bridged by radius 2
  ok::ClusterScratch scratch(c.x.size());
  std::vector<std::int32_t> labels(c.x.size());
  ok::ClusterParams p;
  p.min_size = 10;
  auto r = ok::euclidean_cluster_organized({c.view(), w, h}, mask, p, scratch, labels);
  ASSERT_TRUE(r);
  EXPECT_EQ(*r, 2U);
  EXPECT_EQ(labels[0], 0);
  EXPECT_EQ(labels[25], 1);
  EXPECT_EQ(labels[39], 1);
  EXPECT_EQ(labels[30], -1);
  p.pixel_radius = 1;  // now the masked column splits the right wall
  ASSERT_EQ(*ok::euclidean_cluster_organized({c.view(), w, h}, mask, p, scratch, labels), 3U);
}

// On a mask thinned to every s-th row and column (the object stage's budget), pixel_step s visits
// only the grid and must give the partition pixel_step 1 gives on the same mask with the same
// radius: random range images with depth steps, NaN holes and masked blobs, sizes around the
// stride and a SIMD width, radius s and 2s.
TEST(SegCluster, PixelStepOnAThinnedMaskEqualsTheFullWindow) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> unit(0.0F, 1.0F);
  std::size_t compared = 0;
  for (const std::uint32_t s : {2U, 3U, 4U}) {
    for (const std::uint32_t w : {1U, 7U, 8U, 9U, 17U, 64U}) {
      for (int trial = 0; trial < 12; ++trial) {
        const std::uint32_t h = 1 + static_cast<std::uint32_t>(unit(rng) * 40.0F);
        Cloud c;
        std::vector<std::uint8_t> mask(std::size_t{w} * h, 0);
        for (std::uint32_t v = 0; v < h; ++v) {
          for (std::uint32_t u = 0; u < w; ++u) {
            float z = 1.0F + ((u / 5 + v / 7) % 3 == 0 ? 0.1F : 0.0F) + 0.002F * unit(rng);
            if (unit(rng) < 0.05F) z = std::numeric_limits<float>::quiet_NaN();
            c.add((float(u) - float(w) / 2) * 0.0017F * z, (float(v) - float(h) / 2) * 0.0017F * z,
                  z);
            mask[std::size_t{v} * w + u] = (u % s == 0 && v % s == 0 && unit(rng) < 0.9F) ? 1 : 0;
          }
        }
        for (const std::uint32_t radius : {s, 2 * s}) {
          ok::ClusterParams full;
          full.tolerance = 0.012F;
          full.min_size = 2;
          full.pixel_radius = radius;
          ok::ClusterParams grid = full;
          grid.pixel_step = s;
          ok::ClusterScratch a(c.x.size()), b(c.x.size());
          std::vector<std::int32_t> la(c.x.size()), lb(c.x.size());
          auto ra = ok::euclidean_cluster_organized({c.view(), w, h}, mask, full, a, la);
          auto rb = ok::euclidean_cluster_organized({c.view(), w, h}, mask, grid, b, lb);
          ASSERT_TRUE(ra && rb);
          ASSERT_EQ(*ra, *rb) << "s " << s << " w " << w << " h " << h;
          ASSERT_EQ(la, lb) << "s " << s << " w " << w << " h " << h;
          ++compared;
        }
      }
    }
  }
  EXPECT_EQ(compared, 3U * 6U * 12U * 2U);
  ok::ClusterParams bad;
  bad.pixel_radius = 3;
  bad.pixel_step = 2;  // the radius must be a multiple of the step
  ok::ClusterScratch scratch(4);
  std::vector<std::int32_t> labels(4);
  Cloud c;
  for (int k = 0; k < 4; ++k) c.add(0.0F, 0.0F, 1.0F);
  EXPECT_FALSE(ok::euclidean_cluster_organized({c.view(), 2, 2}, {}, bad, scratch, labels));
}

TEST(SegCluster, EveryErrorCode) {
  using Code = ok::ClusterError::Code;
  Cloud c = blobs(10, 1, 0.01F, 1);
  ok::ClusterScratch scratch(c.x.size());
  std::vector<std::int32_t> labels(c.x.size());
  ok::ClusterParams p;
  p.tolerance = 0.0F;
  EXPECT_EQ(ok::euclidean_cluster(c.view(), {}, p, scratch, labels).error().code, Code::BAD_PARAMS);
  p = {};
  p.min_size = 10, p.max_size = 5;
  EXPECT_EQ(ok::euclidean_cluster(c.view(), {}, p, scratch, labels).error().code, Code::BAD_PARAMS);
  p = {};
  p.pixel_radius = 0;
  EXPECT_EQ(ok::euclidean_cluster_organized({c.view(), 5, 2}, {}, p, scratch, labels).error().code,
            Code::BAD_PARAMS);
  ok::ClusterScratch small(3);
  EXPECT_EQ(ok::euclidean_cluster(c.view(), {}, {}, small, labels).error().code,
            Code::SCRATCH_TOO_SMALL);
  Cloud far;
  far.add(-3e38F, -3e38F, -3e38F), far.add(3e38F, 3e38F, 3e38F);
  ok::ClusterScratch s2(2);
  auto overflow = ok::euclidean_cluster(far.view(), {}, {}, s2, labels);
  ASSERT_FALSE(overflow);
  EXPECT_EQ(overflow.error().code, Code::GRID_OVERFLOW);
  EXPECT_FALSE(overflow.error().to_string().empty());
}

TEST(SegClusterStats, BoxAlongAxesAndRotated) {
  // A 0.4 x 0.2 x 0.1 grid of points rotated 30 degrees about z, centred at (1, 2, 3).
  Cloud c;
  const float ca = std::cos(0.5235988F), sa = std::sin(0.5235988F);
  for (int i = 0; i <= 20; ++i) {
    for (int j = 0; j <= 10; ++j) {
      for (int k = 0; k <= 5; ++k) {
        const float a = -0.2F + 0.02F * float(i), b = -0.1F + 0.02F * float(j),
                    e = -0.05F + 0.02F * float(k);
        c.add(1.0F + ca * a - sa * b, 2.0F + sa * a + ca * b, 3.0F + e);
      }
    }
  }
  std::vector<std::int32_t> labels(c.x.size(), 0);
  labels[0] = -1;  // one unlabelled point is ignored
  std::vector<ok::ClusterMoments> moments(2);
  std::vector<ok::ClusterStats> stats(2);
  ok::cluster_stats(c.view(), labels, moments, stats);
  EXPECT_EQ(stats[0].points, c.x.size() - 1);
  EXPECT_EQ(stats[1].points, 0U);
  EXPECT_NEAR(stats[0].centroid[2], 3.0F, 1e-3F);
  const float obb_len = stats[0].obb_max[0] - stats[0].obb_min[0];
  EXPECT_NEAR(obb_len, 0.4F, 1e-3F);
  EXPECT_NEAR(stats[0].obb_max[1] - stats[0].obb_min[1], 0.2F, 1e-3F);
  EXPECT_NEAR(std::fabs(stats[0].obb_axes[0]), ca, 1e-3F);  // first axis along the long side
  EXPECT_GT(stats[0].bbox_max[0] - stats[0].bbox_min[0], 0.4F * ca);
  EXPECT_GT(stats[0].covariance[0], 0.0F);
}

void expect_same_stats(const std::vector<ok::ClusterStats>& a,
                       const std::vector<ok::ClusterStats>& b) {
  ASSERT_EQ(a.size(), b.size());
  for (std::size_t c = 0; c < a.size(); ++c) {
    EXPECT_EQ(a[c].points, b[c].points) << c;
    EXPECT_EQ(a[c].centroid, b[c].centroid) << c;
    EXPECT_EQ(a[c].covariance, b[c].covariance) << c;
    EXPECT_EQ(a[c].bbox_min, b[c].bbox_min) << c;
    EXPECT_EQ(a[c].bbox_max, b[c].bbox_max) << c;
    EXPECT_EQ(a[c].obb_axes, b[c].obb_axes) << c;
    EXPECT_EQ(a[c].obb_min, b[c].obb_min) << c;
    EXPECT_EQ(a[c].obb_max, b[c].obb_max) << c;
  }
}

TEST(SegClusterStats, ListedEqualsFullScanAndDirectCounts) {
  // Runs of equal labels (length 1..12, ids interleaved), unlabelled gaps; the member list holds
  // every index (label -1 entries are skipped) or only the labelled ones: bit-identical to the full
  // scan.
  std::mt19937 rng(5);
  std::uniform_real_distribution<float> coord(-1.0F, 1.0F);
  Cloud c;
  std::vector<std::int32_t> labels;
  while (c.x.size() < 3000) {
    const auto label = static_cast<std::int32_t>(rng() % 6) - 1;  // -1..4; cluster 5 stays empty
    for (auto k = rng() % 12 + 1; k > 0; --k) {
      c.add(coord(rng) + float(label), coord(rng), 100.0F + coord(rng)), labels.push_back(label);
    }
  }
  std::vector<std::uint32_t> all(c.x.size()), labelled;
  std::iota(all.begin(), all.end(), 0U);
  for (const std::uint32_t i : all) {
    if (labels[i] >= 0) { labelled.push_back(i); }
  }
  std::vector<ok::ClusterMoments> m(6);
  std::vector<ok::ClusterStats> full(6), listed_all(6), listed(6);
  ok::cluster_stats(c.view(), labels, m, full);
  ok::cluster_stats_listed(c.view(), labels, all, m, listed_all);
  ok::cluster_stats_listed(c.view(), labels, labelled, m, listed);
  expect_same_stats(full, listed_all);
  expect_same_stats(full, listed);
  for (std::int32_t id = 0; id < 5; ++id) {  // counts and boxes against a direct loop
    std::size_t n = 0;
    float lo = std::numeric_limits<float>::infinity();
    for (std::size_t i = 0; i < c.x.size(); ++i) {
      if (labels[i] == id) { ++n, lo = std::min(lo, c.z[i]); }
    }
    EXPECT_EQ(full[static_cast<std::size_t>(id)].points, n);
    EXPECT_EQ(full[static_cast<std::size_t>(id)].bbox_min[2], lo);
    EXPECT_NEAR(full[static_cast<std::size_t>(id)].centroid[0], float(id), 0.1F);
  }
  EXPECT_EQ(full[5].points, 0U);
}

TEST(SegClusterStats, ListedMembersOfOrganizedClustering) {
  const std::uint32_t w = 32, h = 24;
  Cloud c;
  std::vector<std::uint8_t> mask;
  for (std::uint32_t v = 0; v < h; ++v) {
    for (std::uint32_t u = 0; u < w; ++u) {
      const float z = (u / 8 + v / 6) % 2 == 0 ? 1.0F : 1.2F;  // a checkerboard of two depths
      c.add(0.002F * float(u), 0.002F * float(v), z);
      mask.push_back((u * 7 + v * 3) % 11 == 0 ? 0 : 1);
    }
  }
  ok::ClusterParams p;
  p.min_size = 10;
  ok::ClusterScratch scratch(c.x.size());
  std::vector<std::int32_t> labels(c.x.size());
  auto r = ok::euclidean_cluster_organized({c.view(), w, h}, mask, p, scratch, labels);
  ASSERT_TRUE(r) << r.error().to_string();
  ASSERT_GT(*r, 1U);
  EXPECT_EQ(scratch.listed_members().size(),
            static_cast<std::size_t>(std::count(mask.begin(), mask.end(), std::uint8_t{1})));
  std::vector<ok::ClusterMoments> m(*r);
  std::vector<ok::ClusterStats> full(*r), listed(*r);
  ok::cluster_stats(c.view(), labels, m, full);
  ok::cluster_stats_listed(c.view(), labels, scratch.listed_members(), m, listed);
  expect_same_stats(full, listed);
  ASSERT_TRUE(ok::euclidean_cluster(c.view(), mask, p, scratch, labels));
  EXPECT_TRUE(scratch.listed_members().empty());  // order[] is in cell order there
}

}  // namespace
