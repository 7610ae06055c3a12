// clear_table and serve_a_meal as plans (manipulation/table_tasks.hpp): who moves, in which order,
// to which spot, and why everything else stays.
#include <cmath>

#include <gtest/gtest.h>

#include "manipulation/table_tasks.hpp"

namespace orthoflow::manipulation {
namespace {

using Eigen::Vector2d;
using Eigen::Vector3d;

std::vector<std::uint32_t> tracks(const TaskPlan& plan) {
  std::vector<std::uint32_t> out;
  for (const TaskMove& m : plan.moves) out.push_back(m.track);
  return out;
}

StayReason stay_of(const TaskPlan& plan, std::uint32_t track) {
  for (const TaskStay& s : plan.stays)
    if (s.track == track) return s.reason;
  ADD_FAILURE() << "track " << track << " is not among the stays";
  return StayReason::UNKNOWN;
}

// Every move's footprint lies in the area, clear by the gap of everything that stays there and of
// every other move's.
void expect_every_place_fits(const TaskPlan& plan, const ClearTableOptions& options) {
  for (std::size_t i = 0; i < plan.moves.size(); ++i) {
    std::vector<Footprint> others = plan.occupied;
    for (std::size_t k = 0; k < plan.moves.size(); ++k)
      if (k != i) others.push_back({plan.moves[k].place, plan.moves[k].radius_m});
    EXPECT_TRUE(fits_in_area(options.area, {plan.moves[i].place, plan.moves[i].radius_m}, others,
                             options.gap_m))
        << "move " << i << " at " << plan.moves[i].place.transpose();
  }
}

TEST(ClearTable, NearestFirstToFreeSpotsAndEveryStayHasItsReason) {
  const std::vector<TableObject> objects{
      {1, "mug", Vector3d(0.30, -0.30, 0.05), 0.05},    // 0.42 m from the base
      {2, "bottle", Vector3d(0.50, 0.10, 0.10), 0.04},  // 0.51 m
      {3, "plate", Vector3d(0.20, -0.10, 0.01), 0.12},  // a table item
      {4, "", Vector3d(0.25, 0.00, 0.04), 0.04},        // Unknown
      {5, "bowl", Vector3d(-0.42, -0.52, 0.03), 0.06},  // already in the area, on its first spot
      {6, "cup", Vector3d(0.10, 0.05, 0.05), 0.04},     // 0.11 m: first
  };
  ClearTableOptions options;
  options.area = {Vector2d(-0.5, -0.6), Vector2d(-0.2, -0.3)};  // 2 x 2 spots of 0.15 m
  options.table_items = {"plate"};
  const TaskPlan plan = plan_clear_table(objects, options);
  EXPECT_EQ(tracks(plan), (std::vector<std::uint32_t>{6, 1, 2}));
  EXPECT_FALSE(plan.packed) << "the grid has a spot for each";
  ASSERT_EQ(plan.moves.size(), 3U);
  EXPECT_TRUE(plan.moves[0].place.isApprox(Vector2d(-0.275, -0.525))) << "the bowl holds spot 1";
  EXPECT_TRUE(plan.moves[1].place.isApprox(Vector2d(-0.425, -0.375)));
  EXPECT_TRUE(plan.moves[2].place.isApprox(Vector2d(-0.275, -0.375)));
  EXPECT_DOUBLE_EQ(plan.moves[1].radius_m, 0.05) << "a move carries its object's footprint";
  ASSERT_EQ(plan.occupied.size(), 1U);
  EXPECT_TRUE(plan.occupied[0].centre.isApprox(Vector2d(-0.42, -0.52)));
  EXPECT_EQ(stay_of(plan, 3), StayReason::TABLE_ITEM);
  EXPECT_EQ(stay_of(plan, 4), StayReason::UNKNOWN);
  EXPECT_EQ(stay_of(plan, 5), StayReason::IN_PLACE);
  EXPECT_EQ(plan.stays.size(), 3U);
  // One more object than the grid's free spots: every place is packed by footprint instead.
  std::vector<TableObject> more = objects;
  more.push_back({7, "spoon", Vector3d(0.60, 0.0, 0.01), 0.02});
  const TaskPlan packed = plan_clear_table(more, options);
  EXPECT_TRUE(packed.packed);
  EXPECT_EQ(tracks(packed), (std::vector<std::uint32_t>{6, 1, 2, 7}));
  // The first cup: the first row that fits it is 4 cm in (its radius); along it, the first place
  // 15 cm (0.06 + 0.04 + the 5 cm gap) from the bowl's centre: dx >= sqrt(0.15^2 - 0.04^2) =
  // 0.1446.
  EXPECT_NEAR(packed.moves[0].place.x(), -0.27, 1e-9);
  EXPECT_NEAR(packed.moves[0].place.y(), -0.56, 1e-9);
  expect_every_place_fits(packed, options);
}

TEST(ClearTable, PlacesAreSizedByEachFootprintNotOneGridForAll) {
  // The demo's area (0.36 x 0.35 m): the 0.15 m grid has four spots for anything; packed by
  // footprint, cans (3.3 cm) take nine, in rows that interleave.
  ClearTableOptions options;
  options.area = {Vector2d(0.20, -0.50), Vector2d(0.56, -0.15)};
  std::vector<TableObject> four;
  for (std::uint32_t k = 0; k < 4; ++k)
    four.push_back({k, "can", Vector3d(-0.3, 0.1 + 0.01 * k, 0.06), 0.033});
  EXPECT_FALSE(plan_clear_table(four, options).packed) << "four: the grid's spots";
  std::vector<TableObject> cans;
  for (std::uint32_t k = 0; k < 12; ++k)
    cans.push_back({k, "can", Vector3d(-0.3, 0.1 + 0.01 * k, 0.06), 0.033});
  const TaskPlan plan = plan_clear_table(cans, options);
  EXPECT_TRUE(plan.packed);
  EXPECT_EQ(plan.moves.size(), 9U);
  EXPECT_EQ(plan.stays.size(), 3U);
  for (const TaskStay& s : plan.stays) EXPECT_EQ(s.reason, StayReason::NO_ROOM);
  expect_every_place_fits(plan, options);
  // Two flasks (7 cm) and three bottles (4.5 cm) fit too: five objects, where the grid has four.
  const std::vector<TableObject> mixed{{1, "flask", Vector3d(0.1, 0.3, 0.06), 0.07},
                                       {2, "flask", Vector3d(0.1, 0.4, 0.06), 0.07},
                                       {3, "bottle", Vector3d(0.1, 0.5, 0.06), 0.045},
                                       {4, "bottle", Vector3d(0.1, 0.6, 0.06), 0.045},
                                       {5, "bottle", Vector3d(0.1, 0.7, 0.06), 0.045}};
  const TaskPlan five = plan_clear_table(mixed, options);
  EXPECT_EQ(tracks(five), (std::vector<std::uint32_t>{1, 2, 3, 4, 5}));
  expect_every_place_fits(five, options);
}

TEST(ClearTable, AFullAreaLeavesTheRestWithNoRoom) {
  const std::vector<TableObject> objects{{1, "mug", Vector3d(0.3, 0, 0), 0.05},
                                         {2, "mug", Vector3d(0.3, 0, 0), 0.05},   // a tie
                                         {3, "tray", Vector3d(0.5, 0, 0), 0.2}};  // wider than it
  ClearTableOptions options;
  options.area = {Vector2d(-0.5, -0.5), Vector2d(-0.35, -0.35)};  // room for one mug
  const TaskPlan plan = plan_clear_table(objects, options);
  EXPECT_EQ(tracks(plan), (std::vector<std::uint32_t>{1}));
  EXPECT_TRUE(plan.moves[0].place.isApprox(Vector2d(-0.45, -0.45)));
  EXPECT_EQ(stay_of(plan, 2), StayReason::NO_ROOM);
  EXPECT_EQ(stay_of(plan, 3), StayReason::NO_ROOM);
  for (const double step : {0.0, -0.01, std::nan("")}) {
    options.step_m = step;
    EXPECT_TRUE(plan_clear_table(objects, options).moves.empty()) << "no grid: no place";
  }
  options.step_m = 1e-12;  // bounded: at most 1000 places along a side
  EXPECT_EQ(tracks(plan_clear_table(objects, options)), (std::vector<std::uint32_t>{1}));
}

TEST(ClearTable, AFootprintFitsInsideTheAreaAndClearOfTheOthers) {
  const TableArea area{Vector2d(0, 0), Vector2d(0.3, 0.2)};
  const Footprint others[] = {{Vector2d(0.05, 0.05), 0.05}};
  EXPECT_TRUE(fits_in_area(area, {Vector2d(0.25, 0.05), 0.05}, others, 0.1)) << "exactly";
  EXPECT_FALSE(fits_in_area(area, {Vector2d(0.249, 0.05), 0.05}, others, 0.1));
  EXPECT_FALSE(fits_in_area(area, {Vector2d(0.26, 0.05), 0.05}, {}, 0.1)) << "over the edge";
  EXPECT_TRUE(fits_in_area(area, {Vector2d(0.3, 0.2), 0.0}, {}, 0.1)) << "a point on the corner";
  EXPECT_FALSE(fits_in_area(area, {Vector2d(0.2, 0.1), -0.01}, {}, 0.1));
  EXPECT_FALSE(fits_in_area(area, {Vector2d(std::nan(""), 0.1), 0.01}, {}, 0.1));
  EXPECT_FALSE(fits_in_area(area, {Vector2d(0.2, 0.1), INFINITY}, {}, 0.1));
  EXPECT_DOUBLE_EQ(footprint_radius(Vector3d(0.12, 0.08, 0.3)), 0.06);
}

TEST(ServeAMeal, TheNamedCategoriesInOrderToTheUsersPlace) {
  const std::vector<TableObject> objects{
      {1, "bowl", Vector3d(0.40, 0.00, 0.03)},
      {2, "bowl", Vector3d(0.10, 0.20, 0.03)},  // the nearer bowl to the user
      {3, "cup", Vector3d(0.15, 0.50, 0.05)},   // already on the second spot
      {4, "", Vector3d(0.30, 0.30, 0.05)},
      {5, "knife", Vector3d(0.35, -0.2, 0.01)},
  };
  ServeOptions options;
  options.categories = {"bowl", "spoon", "cup"};  // no spoon on the table
  options.user_place = Vector2d(0.0, 0.5);
  const TaskPlan plan = plan_serve_a_meal(objects, options);
  ASSERT_EQ(tracks(plan), (std::vector<std::uint32_t>{2}));
  EXPECT_TRUE(plan.moves[0].place.isApprox(Vector2d(0.0, 0.5)));
  EXPECT_EQ(stay_of(plan, 3), StayReason::IN_PLACE);
  EXPECT_EQ(stay_of(plan, 1), StayReason::NOT_REQUESTED) << "one bowl was asked for";
  EXPECT_EQ(stay_of(plan, 4), StayReason::UNKNOWN);
  EXPECT_EQ(stay_of(plan, 5), StayReason::NOT_REQUESTED);
  EXPECT_STREQ(to_string(StayReason::NO_ROOM), "no_room");
}

}  // namespace
}  // namespace orthoflow::manipulation
