// clear_table and serve_a_meal as plans (manipulation/table_tasks.hpp): who moves, in which order,
// to which spot, and why everything else stays.
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

TEST(ClearTable, NearestFirstToFreeSpotsAndEveryStayHasItsReason) {
  const std::vector<TableObject> objects{
      {1, "mug", Vector3d(0.30, -0.30, 0.05)},    // 0.42 m from the base
      {2, "bottle", Vector3d(0.50, 0.10, 0.10)},  // 0.51 m
      {3, "plate", Vector3d(0.20, -0.10, 0.01)},  // a table item
      {4, "", Vector3d(0.25, 0.00, 0.04)},        // Unknown
      {5, "bowl", Vector3d(-0.42, -0.52, 0.03)},  // already in the area, on its first spot
      {6, "cup", Vector3d(0.10, 0.05, 0.05)},     // 0.11 m: first
  };
  ClearTableOptions options;
  options.area = {Vector2d(-0.5, -0.6), Vector2d(-0.2, -0.3)};  // 2 x 2 spots of 0.15 m
  options.table_items = {"plate"};
  const TaskPlan plan = plan_clear_table(objects, options);
  EXPECT_EQ(tracks(plan), (std::vector<std::uint32_t>{6, 1, 2}));
  ASSERT_EQ(plan.moves.size(), 3U);
  EXPECT_TRUE(plan.moves[0].place.isApprox(Vector2d(-0.275, -0.525))) << "the bowl holds spot 1";
  EXPECT_TRUE(plan.moves[1].place.isApprox(Vector2d(-0.425, -0.375)));
  EXPECT_TRUE(plan.moves[2].place.isApprox(Vector2d(-0.275, -0.375)));
  EXPECT_EQ(stay_of(plan, 3), StayReason::TABLE_ITEM);
  EXPECT_EQ(stay_of(plan, 4), StayReason::UNKNOWN);
  EXPECT_EQ(stay_of(plan, 5), StayReason::IN_PLACE);
  EXPECT_EQ(plan.stays.size(), 3U);
}

TEST(ClearTable, AFullAreaLeavesTheRestWithNoRoom) {
  const std::vector<TableObject> objects{{1, "mug", Vector3d(0.3, 0, 0)},
                                         {2, "mug", Vector3d(0.3, 0, 0)}};  // a tie: track order
  ClearTableOptions options;
  options.area = {Vector2d(-0.5, -0.5), Vector2d(-0.35, -0.35)};  // one spot
  const TaskPlan plan = plan_clear_table(objects, options);
  EXPECT_EQ(tracks(plan), (std::vector<std::uint32_t>{1}));
  EXPECT_EQ(stay_of(plan, 2), StayReason::NO_ROOM);
  options.spacing_m = 0.0;
  EXPECT_TRUE(plan_clear_table(objects, options).moves.empty()) << "no spacing: no spot";
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
