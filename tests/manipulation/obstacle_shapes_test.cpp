// The closed loop's object shapes (issue 21): a tilted GOOD box stood upright on the table, and an
// object box covered by small spheres for the execution manager's path check.
#include <gtest/gtest.h>

#include <array>
#include <cmath>

#include "manipulation/execution_manager.hpp"
#include "manipulation/pick_place_job.hpp"

namespace orthoflow::manipulation {
namespace {

using Eigen::AngleAxisd;
using Eigen::Vector3d;

TEST(UprightBox, ATiltedBoxKeepsItsLengthsAndStandsOnTheTable) {
  ObjectBox box;
  // A 0.07 x 0.07 x 0.25 bottle whose frame has its height on the first axis, tilted 10 degrees.
  box.base_from_object.linear() =
      (AngleAxisd(0.17, Vector3d::UnitY()) * AngleAxisd(-M_PI / 2, Vector3d::UnitY()))
          .toRotationMatrix();
  box.base_from_object.translation() = Vector3d(0.3, -0.4, 0.11);
  box.extents = Vector3d(0.25, 0.07, 0.07);
  const ObjectBox up = upright_box(box, SupportPlane{});
  EXPECT_NEAR(up.extents.z(), 0.25, 1e-12);
  EXPECT_NEAR(up.extents.x(), 0.07, 1e-12);
  EXPECT_NEAR(up.extents.y(), 0.07, 1e-12);
  EXPECT_NEAR(up.base_from_object.linear().col(2).dot(Vector3d::UnitZ()), 1.0, 1e-12);
  EXPECT_NEAR(up.base_from_object.linear().determinant(), 1.0, 1e-12);
  // Its bottom was 1.5 cm below the table: raised onto it.
  EXPECT_NEAR(up.base_from_object.translation().z(), 0.125, 1e-12);
  EXPECT_NEAR(up.base_from_object.translation().x(), 0.3, 1e-12);
}

TEST(CoverBox, SpheresCoverEveryPointOfTheBoxAndAPlateIsNoDome) {
  ObjectBox plate;
  plate.base_from_object.translation() = Vector3d(0.0, -0.4, 0.015);
  plate.extents = Vector3d(0.26, 0.26, 0.03);
  std::array<Obstacle, MAX_BOX_SPHERES> s{};
  const std::size_t n = cover_box(plate, s);
  ASSERT_GT(n, 1U);
  ASSERT_LE(n, MAX_BOX_SPHERES);
  double top = 0.0;
  for (std::size_t k = 0; k < n; ++k) top = std::max(top, s[k].centre.z() + s[k].radius);
  EXPECT_LT(top, 0.08);  // one sphere around the plate would reach 0.15 m up
  // Every corner and the centre of the box is inside some sphere.
  for (int c = 0; c < 9; ++c) {
    const Vector3d p =
        c == 8 ? plate.base_from_object.translation()
               : plate.base_from_object * Vector3d((c & 1) ? 0.13 : -0.13, (c & 2) ? 0.13 : -0.13,
                                                   (c & 4) ? 0.015 : -0.015);
    bool covered = false;
    for (std::size_t k = 0; k < n; ++k) covered |= (p - s[k].centre).norm() <= s[k].radius + 1e-12;
    EXPECT_TRUE(covered) << c;
  }
  // A short output span gets what fits.
  EXPECT_EQ(cover_box(plate, std::span(s).first(3)), 3U);
  // The path check on them: a hand 10 cm above the plate passes, one through it does not.
  const auto spheres = std::span<const Obstacle>(s).first(n);
  EXPECT_FALSE(
      segment_blocked(Vector3d(-0.3, -0.4, 0.13), Vector3d(0.3, -0.4, 0.13), spheres, 0.02));
  EXPECT_TRUE(
      segment_blocked(Vector3d(-0.3, -0.4, 0.02), Vector3d(0.3, -0.4, 0.02), spheres, 0.02));
}

TEST(FingerOpening, OpeningForFingerInvertsFingerForOpening) {
  const JobOptions o;
  for (double m : {0.0, 0.03, 0.07, 0.14})
    EXPECT_NEAR(opening_for_finger(finger_for_opening(m, o), o), m, 1e-12);
  EXPECT_NEAR(opening_for_finger(-5.0, o), o.grasp.hand.max_opening_m, 1e-12);
  EXPECT_NEAR(opening_for_finger(1e6, o), 0.0, 1e-12);
}

}  // namespace
}  // namespace orthoflow::manipulation
