// The table verdict (kernels/table_verdict.hpp) and RANSAC's gravity prior (RansacParams::up): each
// test of the verdict on its own, in its order, and the prior finding a level floor beside a larger
// wall, finding no plane in a wall alone, and giving the scalar twin's plane.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <vector>

#include "core/rng.hpp"
#include "kernels/ransac_plane.hpp"
#include "kernels/table_verdict.hpp"

namespace orthoflow::kernels {
namespace {

constexpr float PI_F = 3.14159265F;

// A 1 m x 0.8 m support polygon (0.8 m^2).
const std::vector<double> HULL_U{0.0, 1.0, 1.0, 0.0};
const std::vector<double> HULL_V{0.0, 0.0, 0.8, 0.8};

Plane plane_tilted(float deg, float d) {
  // A plane whose normal is `deg` from up = (0, -1, 0), leaning about the x axis.
  const float r = deg * PI_F / 180.0F;
  return Plane{{0.0F, -std::cos(r), -std::sin(r)}, d};
}

TEST(TableVerdict, AcceptsALevelLargeTableBelowTheCamera) {
  const std::array<float, 3> up{0.0F, -1.0F, 0.0F};
  const TableJudgement j =
      judge_table(plane_tilted(3.0F, 0.7F), 800, 1000, HULL_U, HULL_V, &up, {});
  EXPECT_EQ(j.reason, TableReason::ACCEPTED);
  EXPECT_NEAR(j.tilt_deg, 3.0F, 1e-3F);
  EXPECT_NEAR(j.area_m2, 0.8F, 1e-6F);
  EXPECT_NEAR(j.share, 0.8F, 1e-6F);
  EXPECT_NEAR(j.height_m, 0.7F, 1e-6F);
}

TEST(TableVerdict, RefusesEachFailingTestWithItsReason) {
  const std::array<float, 3> up{0.0F, -1.0F, 0.0F};
  const TableVerdictParams p;
  EXPECT_EQ(judge_table(plane_tilted(10.5F, 0.7F), 800, 1000, HULL_U, HULL_V, &up, p).reason,
            TableReason::NOT_LEVEL);
  EXPECT_EQ(judge_table(plane_tilted(9.5F, 0.7F), 800, 1000, HULL_U, HULL_V, &up, p).reason,
            TableReason::ACCEPTED);
  // A ceiling: the normal faces the sensor, so it points down.
  EXPECT_EQ(judge_table(Plane{{0.0F, 1.0F, 0.0F}, 0.7F}, 800, 1000, HULL_U, HULL_V, &up, p).reason,
            TableReason::NOT_LEVEL);
  EXPECT_EQ(judge_table(plane_tilted(0.0F, 0.05F), 800, 1000, HULL_U, HULL_V, &up, p).reason,
            TableReason::OUT_OF_RANGE);
  EXPECT_EQ(judge_table(plane_tilted(0.0F, 3.0F), 800, 1000, HULL_U, HULL_V, &up, p).reason,
            TableReason::OUT_OF_RANGE);
  EXPECT_EQ(judge_table(plane_tilted(0.0F, 0.7F), 150, 1000, HULL_U, HULL_V, &up, p).reason,
            TableReason::TOO_SMALL);
  const std::vector<double> small_u{0.0, 0.3, 0.3, 0.0}, small_v{0.0, 0.0, 0.3, 0.3};
  EXPECT_EQ(judge_table(plane_tilted(0.0F, 0.7F), 800, 1000, small_u, small_v, &up, p).reason,
            TableReason::TOO_SMALL);
  // The first failing test is the reason: level before range before size.
  EXPECT_EQ(judge_table(plane_tilted(45.0F, 9.0F), 1, 1000, small_u, small_v, &up, p).reason,
            TableReason::NOT_LEVEL);
  EXPECT_EQ(judge_table(plane_tilted(0.0F, 0.7F), 0, 0, {}, {}, &up, p).reason,
            TableReason::TOO_SMALL);
}

TEST(TableVerdict, WithoutUpTheLevelTestIsSkippedAndTheOthersHold) {
  const TableJudgement wall =
      judge_table(Plane{{0.0F, 0.0F, -1.0F}, 1.2F}, 800, 1000, HULL_U, HULL_V, nullptr, {});
  EXPECT_EQ(wall.reason, TableReason::ACCEPTED);
  EXPECT_TRUE(std::isnan(wall.tilt_deg));
  EXPECT_EQ(
      judge_table(Plane{{0.0F, 0.0F, -1.0F}, 1.2F}, 50, 1000, HULL_U, HULL_V, nullptr, {}).reason,
      TableReason::TOO_SMALL);
}

TEST(TableVerdict, NonFinitePlanesAndUpsAreRefused) {
  const float nan = std::numeric_limits<float>::quiet_NaN();
  const std::array<float, 3> up{0.0F, -1.0F, 0.0F}, bad_up{nan, nan, nan};
  EXPECT_NE(judge_table(Plane{{nan, nan, nan}, 0.7F}, 800, 1000, HULL_U, HULL_V, &up, {}).reason,
            TableReason::ACCEPTED);
  EXPECT_NE(judge_table(plane_tilted(0.0F, 0.7F), 800, 1000, HULL_U, HULL_V, &bad_up, {}).reason,
            TableReason::ACCEPTED);
  EXPECT_NE(judge_table(plane_tilted(0.0F, nan), 800, 1000, HULL_U, HULL_V, &up, {}).reason,
            TableReason::ACCEPTED);
}

TEST(TableVerdict, PolygonAreaIsTheShoelaceOfEitherWinding) {
  EXPECT_DOUBLE_EQ(polygon_area(HULL_U, HULL_V), 0.8);
  const std::vector<double> cw_u{0.0, 0.0, 1.0, 1.0}, cw_v{0.0, 0.8, 0.8, 0.0};
  EXPECT_DOUBLE_EQ(polygon_area(cw_u, cw_v), 0.8);
  EXPECT_DOUBLE_EQ(polygon_area(std::vector<double>{0.0, 1.0}, std::vector<double>{0.0, 1.0}), 0.0);
  EXPECT_DOUBLE_EQ(polygon_area({}, {}), 0.0);
}

struct Cloud {
  std::vector<float> x, y, z;
  void add(float px, float py, float pz) { x.push_back(px), y.push_back(py), z.push_back(pz); }
  [[nodiscard]] PointsView view() const { return {x, y, z}; }
};

/// A wall 1.5 m ahead (3,000 points) and a level floor 0.8 m below the camera (2,000 points), with
/// 2 mm noise, in the camera frame (y down, z forward).
Cloud wall_and_floor(bool with_floor) {
  core::Rng rng(7);
  Cloud c;
  const auto noise = [&] { return static_cast<float>(rng.uniform(-0.002, 0.002)); };
  for (int i = 0; i < 3000; ++i)
    c.add(static_cast<float>(rng.uniform(-1.0, 1.0)), static_cast<float>(rng.uniform(-0.8, 0.8)),
          1.5F + noise());
  for (int i = 0; with_floor && i < 2000; ++i)
    c.add(static_cast<float>(rng.uniform(-1.0, 1.0)), 0.8F + noise(),
          static_cast<float>(rng.uniform(0.5, 1.45)));
  return c;
}

TEST(RansacGravityPrior, FindsTheLevelFloorBesideALargerWall) {
  const Cloud c = wall_and_floor(true);
  std::vector<std::uint32_t> inliers(c.x.size());
  RansacParams p;
  p.tau = 0.01F;
  auto free = ransac_plane(c.view(), p, inliers);
  ASSERT_TRUE(free.has_value());
  EXPECT_GT(std::fabs(free->plane.normal[2]), 0.99F);  // the wall: the dominant plane
  p.up = {0.0F, -1.0F, 0.0F};
  p.max_tilt_deg = 20.0F;
  auto level = ransac_plane(c.view(), p, inliers);
  ASSERT_TRUE(level.has_value());
  EXPECT_GT(-level->plane.normal[1], 0.999F);  // the floor, facing the sensor: up
  EXPECT_NEAR(level->plane.d, 0.8F, 0.005F);
  EXPECT_GE(level->inliers, 1900U);
  // The scalar twin runs the same draws and takes the same plane.
  auto twin = ransac_plane_scalar(c.view(), p, inliers);
  ASSERT_TRUE(twin.has_value());
  EXPECT_EQ(twin->inliers, level->inliers);
  EXPECT_NEAR(twin->plane.d, level->plane.d, 1e-5F);
}

TEST(RansacGravityPrior, AWallAloneHasNoLevelPlane) {
  const Cloud c = wall_and_floor(false);
  std::vector<std::uint32_t> inliers(c.x.size());
  RansacParams p;
  p.up = {0.0F, -1.0F, 0.0F};
  p.max_tilt_deg = 20.0F;
  auto none = ransac_plane(c.view(), p, inliers);
  ASSERT_FALSE(none.has_value());
  EXPECT_EQ(none.error().code, RansacError::Code::NO_HYPOTHESIS);
  p.up = {0.0F, 0.0F, -1.0F};  // looking straight down: the "wall" is a floor
  EXPECT_TRUE(ransac_plane(c.view(), p, inliers).has_value());
}

}  // namespace
}  // namespace orthoflow::kernels
