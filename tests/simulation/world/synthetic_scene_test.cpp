// Synthetic Kinect frames checked against the geometry they were rendered from.
#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstring>
#include <set>

#include "simulation/world/synthetic_scene.hpp"

namespace orthoflow::simulation {
namespace {

constexpr std::uint64_t SEED = 42;

struct Rendered {
  Scene scene;
  kernels::PointCloud cloud;
};

Rendered render(const SceneConfig& config, std::uint64_t seed, const RenderOptions& options = {}) {
  Rendered r{make_scene(config, seed), kernels::PointCloud{}};
  core::Rng rng(seed ^ 0x5EEDULL);
  render_scene(r.scene, options, rng, r.cloud);
  return r;
}

/// The same field of view at half resolution (320x240): a quarter of the rays, for quicker tests.
RenderOptions half_resolution() {
  RenderOptions o;
  o.intrinsics = DepthIntrinsics{287.9, 287.9, 159.5, 119.5, 320, 240};
  return o;
}

Vec3 point(const kernels::PointCloud& c, std::size_t i) { return {c.x()[i], c.y()[i], c.z()[i]}; }

TEST(SyntheticScene, OrganizedLayoutWithNanExactlyWhereNoReading) {
  const Rendered r = render(SceneConfig{}, SEED);
  ASSERT_EQ(r.cloud.width(), 640U);
  ASSERT_EQ(r.cloud.height(), 480U);
  ASSERT_TRUE(r.cloud.has(kernels::Field::RGB));
  ASSERT_TRUE(r.cloud.has(kernels::Field::LABEL));
  std::size_t table = 0, objects = 0, none = 0;
  for (std::size_t i = 0; i < r.cloud.size(); ++i) {
    const std::uint32_t l = r.cloud.label()[i];
    const bool nan =
        std::isnan(r.cloud.x()[i]) || std::isnan(r.cloud.y()[i]) || std::isnan(r.cloud.z()[i]);
    ASSERT_EQ(nan, l == LABEL_NONE) << "pixel " << i;
    if (!nan) {
      ASSERT_TRUE(std::isnan(r.cloud.x()[i]) == false && std::isnan(r.cloud.z()[i]) == false);
    }
    table += l == LABEL_TABLE;
    objects += l >= OBJECT_LABEL_BASE;
    none += l == LABEL_NONE;
  }
  EXPECT_GT(table, 30000U);
  EXPECT_GT(objects, 2000U);
  EXPECT_GT(none, 100U);
  EXPECT_GE(r.scene.objects.size(), 4U);
}

TEST(SyntheticScene, TablePointsLieOnThePlaneWithinTheNoiseModel) {
  const RenderOptions options = half_resolution();
  for (std::uint64_t seed : {1ULL, 2ULL}) {
    const Rendered r = render(SceneConfig{}, seed, options);
    const TableFrame f = table_frame(r.scene.table);
    double sum_sq = 0.0;
    std::size_t n = 0;
    for (std::size_t i = 0; i < r.cloud.size(); ++i) {
      if (r.cloud.label()[i] != LABEL_TABLE) { continue; }
      const Vec3 p = point(r.cloud, i);
      const double dist = dot(f.normal, p) + f.d;
      ASSERT_LE(std::fabs(dist), depth_error_bound_m(p[2], options.depth))
          << "seed " << seed << " pixel " << i;
      // Inside the table rectangle (up to the noise, which moves points along their ray).
      const Vec3 q = p - f.center;
      ASSERT_LE(std::fabs(dot(q, f.right)), r.scene.table.width_m / 2 + 0.05);
      ASSERT_LE(std::fabs(dot(q, f.forward)), r.scene.table.depth_m / 2 + 0.05);
      const double step = depth_step_m(p[2], options.depth);
      sum_sq += dist * dist / (step * step);
      ++n;
    }
    ASSERT_GT(n, 2500U);
    // Along the ray the error is about sqrt(sigma_raw^2 + 1/12) steps; the plane distance is
    // smaller.
    EXPECT_LT(std::sqrt(sum_sq / static_cast<double>(n)), 0.6);
  }
}

TEST(SyntheticScene, ObjectPointsStandOnTheTableInsideTheirBoundingCylinder) {
  const RenderOptions options = half_resolution();
  const Rendered r = render(SceneConfig{10, false, {}, 5, true}, 7, options);
  const TableFrame f = table_frame(r.scene.table);
  std::vector<std::size_t> seen(r.scene.objects.size(), 0);
  for (std::size_t i = 0; i < r.cloud.size(); ++i) {
    const int id = object_of_label(r.cloud.label()[i]);
    if (id < 0) { continue; }
    ASSERT_LT(static_cast<std::size_t>(id), r.scene.objects.size());
    const PlacedObject& o = r.scene.objects[static_cast<std::size_t>(id)];
    const Vec3 p = point(r.cloud, i);
    const double tol = depth_error_bound_m(p[2], options.depth);
    const auto pose = object_pose(f, o);
    const Vec3 rel = p - Vec3{pose[3], pose[7], pose[11]};
    const double up = dot(rel, f.normal);
    const Vec3 radial = rel - up * f.normal;
    ASSERT_GT(dot(f.normal, p) + f.d, -tol);
    ASSERT_GE(up, -tol);
    ASSERT_LE(up, o.model.height + tol);
    ASSERT_LE(std::sqrt(dot(radial, radial)), o.model.footprint_radius + tol);
    ++seen[static_cast<std::size_t>(id)];
  }
  EXPECT_GT(std::count_if(seen.begin(), seen.end(), [](std::size_t s) { return s > 20; }), 3);
}

TEST(SyntheticScene, SameSeedSameBytesDifferentSeedDifferent) {
  const Rendered a = render(SceneConfig{}, SEED, half_resolution());
  const Rendered b = render(SceneConfig{}, SEED, half_resolution());
  const Rendered c = render(SceneConfig{}, SEED + 1, half_resolution());
  auto same = [](const kernels::PointCloud& p, const kernels::PointCloud& q) {
    return std::memcmp(p.x().data(), q.x().data(), p.size() * 4) == 0 &&
           std::memcmp(p.y().data(), q.y().data(), p.size() * 4) == 0 &&
           std::memcmp(p.z().data(), q.z().data(), p.size() * 4) == 0 &&
           std::memcmp(p.rgb().data(), q.rgb().data(), p.size() * 4) == 0 &&
           std::memcmp(p.label().data(), q.label().data(), p.size() * 4) == 0;
  };
  EXPECT_TRUE(same(a.cloud, b.cloud));
  EXPECT_FALSE(same(a.cloud, c.cloud));
}

/// The central @p w x @p h window of the 640x480 camera (same rays, fewer of them: quicker tests).
RenderOptions window(std::uint32_t w, std::uint32_t h) {
  RenderOptions o;
  o.intrinsics.cx -= (640 - w) / 2.0;
  o.intrinsics.cy -= (480 - h) / 2.0;
  o.intrinsics.width = w;
  o.intrinsics.height = h;
  return o;
}

TEST(SyntheticScene, DepthIsQuantisedToTheDisparitySteps) {
  const RenderOptions options = window(96, 72);
  const DepthTable table = make_depth_table(options.depth);
  const std::set<float> levels(table.begin(), table.end());
  const Scene scene = make_scene(SceneConfig{}, SEED);
  std::set<float> at_centre;
  kernels::PointCloud cloud;
  for (std::uint64_t s = 0; s < 10; ++s) {
    core::Rng rng(s);
    render_scene(scene, options, rng, cloud);
    for (float z : cloud.z()) {
      if (!std::isnan(z)) { ASSERT_EQ(levels.count(z), 1U) << z << " is not a Kinect depth level"; }
    }
    const std::size_t centre = 36 * 96 + 48;
    if (!std::isnan(cloud.z()[centre])) { at_centre.insert(cloud.z()[centre]); }
  }
  // The noise spreads one pixel's depth over a few levels, one step (> 1 mm at >= 0.7 m) apart.
  ASSERT_GE(at_centre.size(), 2U);
  EXPECT_LE(at_centre.size(), 7U);
  for (auto it = std::next(at_centre.begin()); it != at_centre.end(); ++it) {
    EXPECT_GT(*it - *std::prev(it), 1e-3F);
  }
}

TEST(SyntheticScene, ProjectorBaselineCastsShadowsBesideObjects) {
  RenderOptions with = half_resolution();
  with.depth.sigma_raw = 0.0;
  RenderOptions without = with;
  without.projector_x_m = 0.0;
  const Rendered a = render(SceneConfig{8, false, {}, 5, true}, 11, with);
  const Rendered b = render(SceneConfig{8, false, {}, 5, true}, 11, without);
  std::size_t shadows = 0, explained = 0;
  for (std::size_t i = 0; i < a.cloud.size(); ++i) {
    if (a.cloud.label()[i] != LABEL_NONE || b.cloud.label()[i] == LABEL_NONE) { continue; }
    ++shadows;
    // The projector sits at +x, so the occluder is to the right of its shadow on the same row, at
    // most f b / z_min = 43 pixels away at this resolution (unless the camera does not see it).
    const std::size_t row_end = (i / 320 + 1) * 320;
    bool occluder = false;
    for (std::size_t j = i + 1; j < std::min(row_end, i + 45) && !occluder; ++j) {
      const std::uint32_t l = b.cloud.label()[j];
      occluder = l >= OBJECT_LABEL_BASE || (l == LABEL_TABLE && b.cloud.label()[i] == LABEL_FLOOR);
    }
    explained += occluder;
  }
  EXPECT_GT(shadows, 100U);
  std::printf("[ info ] %zu shadow pixels, %zu with a visible occluder\n", shadows, explained);
  EXPECT_GE(static_cast<double>(explained), 0.97 * static_cast<double>(shadows));
}

TEST(SyntheticScene, PlacementKeepsObjectsApartOrTouchingAndOnTheTable) {
  for (bool touching : {false, true}) {
    const Scene s = make_scene(SceneConfig{12, touching, {}, 5, true}, 5);
    ASSERT_GE(s.objects.size(), 6U);
    for (std::size_t i = 0; i < s.objects.size(); ++i) {
      const PlacedObject& a = s.objects[i];
      EXPECT_LE(std::fabs(a.table_x) + a.model.footprint_radius, s.table.width_m / 2);
      EXPECT_LE(std::fabs(a.table_y) + a.model.footprint_radius, s.table.depth_m / 2);
      for (std::size_t j = 0; j < i; ++j) {
        const PlacedObject& b = s.objects[j];
        const double dist = std::hypot(a.table_x - b.table_x, a.table_y - b.table_y);
        EXPECT_GE(dist, (a.model.footprint_radius + b.model.footprint_radius) * (1 - 1e-9));
      }
    }
    if (touching) {
      const PlacedObject& a = s.objects[0];
      const PlacedObject& b = s.objects[1];
      EXPECT_NEAR(std::hypot(a.table_x - b.table_x, a.table_y - b.table_y),
                  a.model.footprint_radius + b.model.footprint_radius, 1e-9);
    }
  }
}

TEST(SyntheticScene, TenObjectFrameReusesTheCloud) {
  const Scene scene =
      make_scene(SceneConfig{10, false, {}, 5, true}, 6);  // a seed where all ten fit
#if defined(__SANITIZE_ADDRESS__)
  const RenderOptions options =
      half_resolution();  // the timing means nothing under ASan: keep it short
#else
  const RenderOptions options;
#endif
  kernels::PointCloud cloud;
  core::Rng rng(1);
  render_scene(scene, options, rng, cloud);
  const float* before = cloud.x().data();
  const auto start = std::chrono::steady_clock::now();
  render_scene(scene, options, rng, cloud);
  const double ms =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  EXPECT_EQ(before, cloud.x().data());  // same buffers: the warm cloud is refilled in place
  EXPECT_EQ(scene.objects.size(), 10U);
  std::printf("[ info ] %ux%u frame with %zu objects rendered in %.1f ms\n", cloud.width(),
              cloud.height(), scene.objects.size(), ms);
  // Speed is measured in bench/simulation/synthetic_bench.cpp, never asserted here.
}

}  // namespace
}  // namespace orthoflow::simulation
