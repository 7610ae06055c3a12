// The closed-loop world's contact rule (simulation/world/table_world.hpp): fingers closing around
// an object hold it, a hand elsewhere holds nothing, a held object follows the hand upright and
// rests on the table when released, one released beyond the edge falls off, a person can move one.
#include <gtest/gtest.h>

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
