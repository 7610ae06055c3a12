// The closed-loop world's contact rule (simulation/world/table_world.hpp): fingers closing around
// an object hold it, a hand elsewhere holds nothing, a held object follows the hand upright and
// rests on the table when released, one released beyond the edge falls off, a person can move one,
// and what is between the fingers stops them at its width.
#include <gtest/gtest.h>

#include <cmath>
#include <optional>

#include "simulation/world/table_world.hpp"

namespace orthoflow::simulation {
namespace {

Scene one_mug() {
  Scene scene;
  PlacedObject mug;
  mug.model = make_object_model(Category::MUG, 0);
  mug.table_x = 0.1;
  mug.table_y = -0.1;
  mug.id = 7;
  scene.objects.push_back(mug);
  return scene;
}

/// A point in the sensor frame at table coordinates (x, y, up).
Vec3 at(const TableWorld& w, double x, double y, double up) { return w.table().point(x, y, up); }

TEST(TableWorld, ClosingFingersAroundAnObjectHoldItAndItFollowsTheHand) {
  TableWorld w(one_mug());
  const double h = w.scene().objects[0].model.height,
               r = w.scene().objects[0].model.footprint_radius;
  w.update(at(w, 0.1, -0.1, h / 2), 2 * r + 0.03);  // open, around it
  EXPECT_EQ(w.held(), -1);
  w.update(at(w, 0.1, -0.1, h / 2), 2 * r + 0.01);  // closing, still wider than it
  EXPECT_EQ(w.held(), -1);
  w.update(at(w, 0.1, -0.1, h / 2), 2 * r - 0.01);  // closing past its width
  ASSERT_EQ(w.held(), 0);
  w.update(at(w, 0.3, 0.0, h / 2 + 0.2), 2 * r - 0.02);  // lifted and carried
  const PlacedObject& o = w.scene().objects[0];
  EXPECT_NEAR(o.table_x, 0.3, 1e-9);
  EXPECT_NEAR(o.table_y, 0.0, 1e-9);
  EXPECT_NEAR(o.base_m, 0.2, 1e-9);
  w.update(at(w, 0.3, 0.0, h / 2 + 0.2), 2 * r + 0.02);  // opened: it drops onto the table
  EXPECT_EQ(w.held(), -1);
  EXPECT_NEAR(w.scene().objects[0].base_m, 0.0, 1e-12);
  EXPECT_NEAR(w.scene().objects[0].table_x, 0.3, 1e-9);
}

TEST(TableWorld, WhatIsBetweenTheFingersStopsThemAtItsWidthAndIsHeldThere) {
  TableWorld w(one_mug());
  const double h = w.scene().objects[0].model.height,
               r = w.scene().objects[0].model.footprint_radius;
  const Vec3 across = w.table().forward;  // the fingers close along the table's y
  const Vec3 around = at(w, 0.1, -0.1, h / 2);
  const std::optional<double> width = w.grip_width(around, across);
  ASSERT_TRUE(width.has_value());
  EXPECT_GT(*width, 0.03) << "the mug's body, not a sliver";
  EXPECT_LE(*width, 2 * r + 1e-9) << "within its footprint";
  EXPECT_FALSE(w.grip_width(at(w, 0.1 + r + GRIP_SLACK_M + 0.01, -0.1, h / 2), across));
  EXPECT_FALSE(w.grip_width(at(w, 0.1, -0.1, h + GRIP_SLACK_M + 0.01), across));
  // Inside the bounding cylinder's slack but beside the solid: the line misses it.
  EXPECT_FALSE(w.grip_width(at(w, 0.1, -0.1 + r + 0.5 * GRIP_SLACK_M, h / 2), w.table().right));
  const HandAxes hand{w.table().right, across, w.table().normal};
  w.update(around, *width + 0.03, hand);
  w.update(around, *width + GRIP_CONTACT_M + 0.002, hand);  // closing, not yet touching
  EXPECT_EQ(w.held(), -1);
  w.update(around, *width, hand);  // stopped by it: touching, held
  ASSERT_EQ(w.held(), 0);
  const Vec3 carried = at(w, 0.4, 0.1, h / 2 + 0.2);
  w.update(carried, *width, hand);
  ASSERT_TRUE(w.grip_width(carried, across).has_value()) << "it stays between the fingers";
  EXPECT_NEAR(*w.grip_width(carried, across), *width, 1e-12);
}

/// The hand's axes turned by @p deg about the table's x axis (right), from @p axes.
HandAxes turned(const TableWorld& w, double deg) {
  const double a = deg * 3.14159265358979323846 / 180.0;
  const Vec3 x = w.table().right, y = w.table().forward, z = w.table().normal;
  const auto mix = [](const Vec3& p, double cp, const Vec3& q, double cq) {
    return Vec3{cp * p[0] + cq * q[0], cp * p[1] + cq * q[1], cp * p[2] + cq * q[2]};
  };
  return {x, mix(y, std::cos(a), z, std::sin(a)), mix(z, std::cos(a), y, -std::sin(a))};
}

TEST(TableWorld, AHeldMugTurnsWithTheHandSpillsPastItsLimitAndSlipsOutFurther) {
  TableWorld w(one_mug());
  const double h = w.scene().objects[0].model.height,
               r = w.scene().objects[0].model.footprint_radius;
  const Vec3 around = at(w, 0.1, -0.1, h / 2);
  w.update(around, 2 * r + 0.03, turned(w, 0.0));
  const double width = *w.grip_width(around, w.table().forward);
  w.update(around, width, turned(w, 0.0));
  ASSERT_EQ(w.held(), 0);
  const Vec3 up = at(w, 0.1, -0.1, h / 2 + 0.2);
  w.update(up, width, turned(w, SPILL_TILT_DEG - 5.0));
  EXPECT_NEAR(w.held_tilt_deg(), SPILL_TILT_DEG - 5.0, 1e-6);
  EXPECT_EQ(w.spills(), 0U);
  w.update(up, width, turned(w, SPILL_TILT_DEG + 5.0));
  EXPECT_EQ(w.spills(), 1U);
  w.update(up, width, turned(w, SPILL_TILT_DEG + 6.0));
  EXPECT_EQ(w.spills(), 1U) << "one spill per carry";
  EXPECT_EQ(w.held(), 0);
  w.update(up, width, turned(w, DROP_TILT_DEG + 1.0));
  EXPECT_EQ(w.held(), -1) << "it slipped out";
  EXPECT_EQ(w.drops(), 1U);
  EXPECT_NEAR(w.scene().objects[0].base_m, 0.0, 1e-12) << "on the table below the hand";
}

TEST(TableWorld, ACanTiltedPastTheSpillLimitDoesNotSpill) {
  Scene scene = one_mug();
  scene.objects[0].model = make_object_model(Category::CAN, 0);
  TableWorld w(scene);
  const double h = w.scene().objects[0].model.height,
               r = w.scene().objects[0].model.footprint_radius;
  const Vec3 around = at(w, 0.1, -0.1, h / 2);
  w.update(around, 2 * r + 0.03, turned(w, 10.0));
  w.update(around, 0.0, turned(w, 10.0));  // taken with the hand already turned: upright
  ASSERT_EQ(w.held(), 0);
  EXPECT_NEAR(w.held_tilt_deg(), 0.0, 1e-6);
  w.update(around, 0.0, turned(w, 10.0 + SPILL_TILT_DEG + 5.0));
  EXPECT_EQ(w.spills(), 0U);
  EXPECT_EQ(w.held(), 0);
}

TEST(TableWorld, AGraspThatMissesLeavesTheObjectWhereItWas) {
  TableWorld w(one_mug());
  const double h = w.scene().objects[0].model.height,
               r = w.scene().objects[0].model.footprint_radius;
  const Vec3 beside = at(w, 0.1 + r + GRIP_SLACK_M + 0.01, -0.1, h / 2);
  w.update(beside, 2 * r + 0.03);
  w.update(beside, 0.0);  // closed beside it
  EXPECT_EQ(w.held(), -1);
  const Vec3 above = at(w, 0.1, -0.1, h + GRIP_SLACK_M + 0.01);
  w.update(above, 2 * r + 0.03);
  w.update(above, 0.0);  // closed above it
  EXPECT_EQ(w.held(), -1);
  w.update(at(w, 0.4, 0.2, 0.3), 0.0);
  EXPECT_NEAR(w.scene().objects[0].table_x, 0.1, 1e-12);
  EXPECT_NEAR(w.scene().objects[0].table_y, -0.1, 1e-12);
}

TEST(TableWorld, AnObjectReleasedBeyondTheEdgeFallsOff) {
  TableWorld w(one_mug());
  const double h = w.scene().objects[0].model.height;
  const double open = 2 * w.scene().objects[0].model.footprint_radius + 0.03;
  w.update(at(w, 0.1, -0.1, h / 2), open);
  w.update(at(w, 0.1, -0.1, h / 2), 0.0);
  ASSERT_EQ(w.held(), 0);
  w.update(at(w, 0.5 * w.scene().table.width_m + 0.2, -0.1, h), 0.0);
  w.update(at(w, 0.5 * w.scene().table.width_m + 0.2, -0.1, h), open);
  EXPECT_EQ(w.scene().objects.size(), 0U);
  EXPECT_EQ(w.fallen(), 1U);
  EXPECT_EQ(w.find(7), -1);
}

TEST(TableWorld, APersonMovesAnObjectButNotOneInTheHand) {
  TableWorld w(one_mug());
  EXPECT_TRUE(w.move_object(0, 0.2, 0.0));
  EXPECT_NEAR(w.scene().objects[0].table_x, 0.2, 1e-12);
  EXPECT_FALSE(w.move_object(3, 0.0, 0.0));
  const double h = w.scene().objects[0].model.height;
  w.update(at(w, 0.2, 0.0, h / 2), 2 * w.scene().objects[0].model.footprint_radius + 0.03);
  w.update(at(w, 0.2, 0.0, h / 2), 0.0);
  ASSERT_EQ(w.held(), 0);
  EXPECT_FALSE(w.move_object(0, 0.0, 0.0));
}

}  // namespace
}  // namespace orthoflow::simulation
