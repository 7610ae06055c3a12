// The fast paths of the organized tabletop chain against their references, on random and
// adversarial inputs: the SIMD polygon prefilter of polygonal_prism (every compiled arch) against
// the scalar twin, pixel_subsample against a plain strided loop, organized clustering against a
// brute-force window graph, cluster_stats with unlabelled gaps against a direct recomputation.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <random>
#include <string>
#include <vector>

#include "kernels/cluster_stats.hpp"
#include "kernels/detail/polygonal_prism_kernel.hpp"
#include "kernels/euclidean_cluster.hpp"
#include "kernels/pixel_subsample.hpp"

namespace ok = orthoflow::kernels;

namespace {

constexpr float NAN_F = std::numeric_limits<float>::quiet_NaN();

struct Cloud {
  std::vector<float> x, y, z;
  ok::PointsView view() const { return {x, y, z}; }
  void add(double a, double b, double c) {
    x.push_back(static_cast<float>(a)), y.push_back(static_cast<float>(b)),
        z.push_back(static_cast<float>(c));
  }
};

/// A tilted table plane (the mOSD one), a random convex hull of @p corners points in it, and a
/// cloud of n points around it: random ones, hull vertices and edge points exactly (then rounded to
/// float), heights exactly at h_min / h_max, NaNs, duplicates; @p scale multiplies every
/// coordinate.
struct PrismCase {
  ok::Plane plane{{0.0F, -0.8F, -0.6F}, 0.6F};
  std::vector<double> hu, hv;
  Cloud cloud;
};

PrismCase make_prism_case(std::size_t n, std::size_t corners, double scale, std::uint32_t seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  PrismCase c;
  std::vector<double> u(corners), v(corners);
  for (std::size_t k = 0; k < corners; ++k) {  // points on a circle: every one is a hull vertex
    const double t = 6.283185307179586 * (double(k) + 0.3 * unit(rng) + 0.5) / double(corners);
    u[k] = 0.5 * scale * std::cos(t), v[k] = 0.4 * scale * std::sin(t);
  }
  std::vector<std::uint32_t> scratch(corners), hull(corners + 1);
  const std::size_t h = ok::convex_hull_2d(u, v, scratch, hull);
  for (std::size_t k = 0; k < h; ++k) { c.hu.push_back(u[hull[k]]), c.hv.push_back(v[hull[k]]); }
  const ok::PlaneBasis b = ok::make_plane_basis(c.plane);
  auto emit = [&](double pu, double pv, double height) {
    double p[3];
    for (std::size_t a = 0; a < 3; ++a) {
      p[a] = b.origin[a] + pu * b.u[a] + pv * b.v[a] + height * b.n[a];
    }
    c.cloud.add(p[0], p[1], p[2]);
  };
  for (std::size_t i = 0; i < n; ++i) {
    const std::size_t k = h == 0 ? 0 : i % h, next = h == 0 ? 0 : (k + 1) % h;
    const double height = (i % 5 == 0) ? 0.005 : (i % 5 == 1) ? 0.5 : 0.3 * unit(rng) + 0.2;
    switch (i % 4) {
      case 0:
        emit(0.7 * scale * unit(rng), 0.6 * scale * unit(rng), height);
        break;
      case 1:
        if (h > 0) {
          emit(c.hu[k], c.hv[k], height);
        } else {
          emit(0, 0, height);
        }
        break;
      case 2:
        if (h > 0) {
          emit(0.5 * (c.hu[k] + c.hu[next]), 0.5 * (c.hv[k] + c.hv[next]), height);
        } else {
          emit(0, 0, height);
        }
        break;
      default:
        c.cloud.add(NAN_F, 0.0, 0.0);
    }
    if (i % 11 == 3 && i > 0) {
      c.cloud.x.back() = c.cloud.x[0], c.cloud.y.back() = c.cloud.y[0],
      c.cloud.z.back() = c.cloud.z[0];
    }
  }
  return c;
}

/// Every compiled arch's polygon kernel against the scalar rule, on the same heights.
void expect_prism_equal(const PrismCase& c, const ok::AxisBox& box) {
  const ok::Prism prism{c.plane, ok::make_plane_basis(c.plane), c.hu, c.hv, 0.005F, 0.5F, box};
  const std::size_t n = c.cloud.x.size();
  std::vector<float> heights(n);
  ok::plane_signed_distance_scalar(c.cloud.view(), c.plane, heights);
  std::vector<std::uint8_t> ref(n), got(n);
  const std::size_t kept =
      ok::detail::prism_mask_range(c.cloud.view(), prism, heights, ref.data(), 0, n);
  ok::detail::PrismEdges edges;
  if (!ok::detail::make_prism_edges(prism, edges)) {
    return;
  }  // the dispatcher then runs the scalar rule
  ok::for_each_available_arch([&](auto arch) {
    // The arch computes its own heights (FMA may move them within the plane_distance.hpp
    // tolerance); for those heights its mask must equal the scalar rule's exactly.
    std::fill(got.begin(), got.end(), std::uint8_t{7});
    std::vector<float> own(n, -1.0F);
    std::vector<std::uint8_t> own_ref(n);
    const std::size_t got_kept =
        ok::detail::PrismPolygonKernel{}(arch, c.cloud.view(), prism, edges, own, got);
    EXPECT_EQ(got_kept,
              ok::detail::prism_mask_range(c.cloud.view(), prism, own, own_ref.data(), 0, n));
    EXPECT_EQ(got, own_ref) << decltype(arch)::name() << " n " << n;
    for (std::size_t i = 0; i < n; ++i) {
      const float tol = 1e-6F * (std::fabs(c.cloud.x[i]) + std::fabs(c.cloud.y[i]) +
                                 std::fabs(c.cloud.z[i]) + 1.0F);
      EXPECT_TRUE((std::isnan(heights[i]) && std::isnan(own[i])) ||
                  std::fabs(own[i] - heights[i]) <= tol)
          << decltype(arch)::name() << " height " << i;
    }
  });
  std::vector<float> h2(n);
  EXPECT_EQ(ok::polygonal_prism_scalar(c.cloud.view(), prism, h2, got), kept);
  EXPECT_EQ(got, ref);
}

class SegPrismFast : public ::testing::TestWithParam<std::size_t> {};

TEST_P(SegPrismFast, EveryArchEqualsScalar) {
  const std::size_t n = GetParam();
  expect_prism_equal(make_prism_case(n, 24, 1.0, 3), {});
  expect_prism_equal(make_prism_case(n, 7, 1e6, 4), {});   // huge coordinates
  expect_prism_equal(make_prism_case(n, 3, 1e-3, 5), {});  // tiny triangle
  ok::AxisBox half;                                        // the box cuts the hull: x <= 0 only
  half.max[0] = 0.0F;
  expect_prism_equal(make_prism_case(n, 24, 1.0, 6), half);
}

INSTANTIATE_TEST_SUITE_P(Sizes, SegPrismFast,
                         ::testing::Values(0, 1, 3, 4, 5, 7, 8, 9, 15, 16, 17, 31, 33, 1000));

TEST(SegPrismFast, LargeAndDegenerateHullsTakeTheExactPath) {
  const PrismCase big = make_prism_case(500, 300, 1.0, 8);  // more than MAX_EDGES vertices
  ASSERT_GT(big.hu.size(), ok::detail::PrismEdges::MAX_EDGES);
  ok::detail::PrismEdges edges;
  const ok::Prism prism{big.plane, ok::make_plane_basis(big.plane), big.hu, big.hv, 0.005F, 0.5F};
  EXPECT_FALSE(ok::detail::make_prism_edges(prism, edges));
  std::vector<float> h(500);
  std::vector<std::uint8_t> ref(500), got(500);
  const std::size_t kept = ok::polygonal_prism_scalar(big.cloud.view(), prism, h, ref);
  EXPECT_GT(kept, 0U);
  EXPECT_EQ(ok::polygonal_prism(big.cloud.view(), prism, h, got), kept);
  EXPECT_EQ(got, ref);
  const double seg_u[] = {0.0, 1.0}, seg_v[] = {0.0, 0.0};  // two vertices: nothing is inside
  const ok::Prism line{big.plane, ok::make_plane_basis(big.plane), seg_u, seg_v, 0.005F, 0.5F};
  EXPECT_FALSE(ok::detail::make_prism_edges(line, edges));
  EXPECT_EQ(ok::polygonal_prism(big.cloud.view(), line, h, got), 0U);
}

TEST(SegPixelSubsample, StridedRoiKeptPixelsInRowMajorOrder) {
  const std::uint32_t w = 37, hgt = 23;
  Cloud c;
  std::mt19937 rng(9);
  std::uniform_real_distribution<float> coord(-2.0F, 2.0F);
  for (std::uint32_t i = 0; i < w * hgt; ++i) {
    c.x.push_back(coord(rng)), c.y.push_back(coord(rng)), c.z.push_back(coord(rng));
    if (i % 7 == 0) { c.y.back() = NAN_F; }
    if (i % 13 == 0) { c.z.back() = std::numeric_limits<float>::infinity(); }
  }
  ok::AxisBox roi{{-1.0F, -1.5F, -3.4e38F}, {1.0F, 1.5F, std::numeric_limits<float>::infinity()}};
  for (std::uint32_t stride : {1U, 2U, 3U, 4U, 7U, 40U}) {
    std::vector<float> ox(w * hgt), oy(w * hgt), oz(w * hgt);
    const std::size_t n = ok::pixel_subsample({c.view(), w, hgt}, stride, roi, {ox, oy, oz});
    std::vector<std::size_t> expected;
    for (std::uint32_t v = stride / 2; v < hgt; v += stride) {
      for (std::uint32_t u = stride / 2; u < w; u += stride) {
        const std::size_t i = std::size_t{v} * w + u;
        const bool in = c.x[i] >= -1.0F && c.x[i] <= 1.0F && c.y[i] >= -1.5F && c.y[i] <= 1.5F &&
                        std::isfinite(c.z[i]);
        if (in) { expected.push_back(i); }
      }
    }
    ASSERT_EQ(n, expected.size()) << "stride " << stride;
    for (std::size_t k = 0; k < n; ++k) {
      EXPECT_EQ(ox[k], c.x[expected[k]]);
      EXPECT_EQ(oy[k], c.y[expected[k]]);
      EXPECT_EQ(oz[k], c.z[expected[k]]);
    }
  }
  std::vector<float> none(1);
  EXPECT_EQ(ok::pixel_subsample({ok::PointsView{}, 0, 0}, 3, roi, {none, none, none}), 0U);
}

/// Brute force over the window graph: pixels within r (Chebyshev) and tolerance, sizes filtered,
/// ids by lowest index (the organized clustering's contract).
std::vector<std::int32_t> window_reference(const Cloud& c, std::uint32_t w, std::uint32_t h,
                                           const std::vector<std::uint8_t>& mask,
                                           const ok::ClusterParams& p) {
  const std::size_t n = std::size_t{w} * h;
  std::vector<std::size_t> parent(n);
  std::iota(parent.begin(), parent.end(), 0U);
  auto find = [&](std::size_t i) {
    while (parent[i] != i) { i = parent[i]; }
    return i;
  };
  auto inc = [&](std::size_t i) {
    return (mask.empty() || mask[i] != 0) && std::isfinite(c.x[i]) && std::isfinite(c.y[i]) &&
           std::isfinite(c.z[i]);
  };
  const auto r = static_cast<long>(p.pixel_radius);
  for (std::size_t i = 0; i < n; ++i) {
    for (std::size_t j = i + 1; j < n && inc(i); ++j) {
      const long du = long(j % w) - long(i % w), dv = long(j / w) - long(i / w);
      if (std::labs(du) > r || dv > r || !inc(j)) { continue; }
      const float dx = c.x[i] - c.x[j], dy = c.y[i] - c.y[j], dz = c.z[i] - c.z[j];
      if (dx * dx + dy * dy + dz * dz <= p.tolerance * p.tolerance) {
        const std::size_t a = find(i), b = find(j);
        parent[std::max(a, b)] = std::min(a, b);
      }
    }
  }
  std::vector<std::size_t> size(n, 0);
  for (std::size_t i = 0; i < n; ++i) { size[find(i)] += inc(i) ? 1U : 0U; }
  std::vector<std::int32_t> label(n, -1), id(n, -2);
  std::int32_t next = 0;
  for (std::size_t i = 0; i < n; ++i) {
    if (!inc(i)) { continue; }
    const std::size_t root = find(i);
    if (id[root] == -2) {
      id[root] = (size[root] >= p.min_size && size[root] <= p.max_size) ? next++ : -1;
    }
    label[i] = id[root];
  }
  return label;
}

TEST(SegClusterFast, OrganizedEqualsWindowGraphReference) {
  const std::uint32_t w = 41, h = 29;
  for (std::uint32_t seed = 0; seed < 6; ++seed) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<float> unit(0.0F, 1.0F);
    Cloud c;
    std::vector<std::uint8_t> mask(std::size_t{w} * h);
    for (std::uint32_t v = 0; v < h; ++v) {
      for (std::uint32_t u = 0; u < w; ++u) {
        // Three surfaces at different depths, isolated spikes, holes, random mask.
        float z = u < 14 ? 1.0F : (v < 15 ? 1.03F : 1.015F);
        z += unit(rng) < 0.05F ? 0.1F : 0.004F * unit(rng);
        c.add((float(u) - 20.0F) * 0.003F * z, (float(v) - 15.0F) * 0.003F * z,
              unit(rng) < 0.05F ? NAN_F : z);
        mask[c.x.size() - 1] = unit(rng) < 0.85F ? 1 : 0;
      }
    }
    for (std::uint32_t radius : {1U, 2U, 3U}) {
      for (std::uint32_t min_size : {1U, 5U}) {
        ok::ClusterParams p;
        p.pixel_radius = radius, p.min_size = min_size, p.max_size = seed % 2 == 0 ? 400U : 100000U;
        ok::ClusterScratch scratch(c.x.size());
        std::vector<std::int32_t> labels(c.x.size(), 99);
        const std::vector<std::uint8_t> m =
            seed == 5 ? std::vector<std::uint8_t>{} : mask;  // empty mask: all
        auto r = ok::euclidean_cluster_organized({c.view(), w, h}, m, p, scratch, labels);
        ASSERT_TRUE(r) << r.error().to_string();
        const auto ref = window_reference(c, w, h, m, p);
        EXPECT_EQ(labels, ref) << "seed " << seed << " radius " << radius << " min " << min_size;
        EXPECT_EQ(*r, std::size_t(*std::max_element(ref.begin(), ref.end()) + 1));
      }
    }
  }
}

TEST(SegClusterFast, StatsSkipUnlabelledGapsExactly) {
  // Labelled points separated by unlabelled gaps of 0..20 (around the 8-label skip) give exactly
  // the statistics of the same labelled points without gaps.
  std::mt19937 rng(21);
  std::uniform_real_distribution<float> coord(-1.0F, 1.0F);
  Cloud full, dense;
  std::vector<std::int32_t> full_labels, dense_labels;
  for (int k = 0; k < 300; ++k) {
    const auto gap = static_cast<int>(rng() % 21);
    for (int g = 0; g < gap; ++g) {
      full.add(NAN_F, NAN_F, NAN_F), full_labels.push_back(g % 2 == 0 ? -1 : -7);
    }
    const float p[3] = {coord(rng), coord(rng) + 2.0F, coord(rng)};
    const auto label = static_cast<std::int32_t>(rng() % 3);
    full.add(p[0], p[1], p[2]), dense.add(p[0], p[1], p[2]);
    full_labels.push_back(label), dense_labels.push_back(label);
  }
  std::vector<ok::ClusterMoments> m1(4), m2(4);
  std::vector<ok::ClusterStats> s1(4), s2(4);
  ok::cluster_stats(full.view(), full_labels, m1, s1);
  ok::cluster_stats(dense.view(), dense_labels, m2, s2);
  for (std::size_t c = 0; c < 4; ++c) {
    EXPECT_EQ(s1[c].points, s2[c].points);
    EXPECT_EQ(s1[c].centroid, s2[c].centroid);
    EXPECT_EQ(s1[c].covariance, s2[c].covariance);
    EXPECT_EQ(s1[c].bbox_min, s2[c].bbox_min);
    EXPECT_EQ(s1[c].obb_max, s2[c].obb_max);
  }
  EXPECT_EQ(s1[3].points, 0U);
  EXPECT_GT(s1[0].points, 50U);
}

}  // namespace
