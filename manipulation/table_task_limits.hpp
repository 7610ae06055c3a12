#pragma once
/// @file
/// @brief (internal) The distances the table-task runner judges by, shared by its life cycle
/// (table_task_runner.cpp), its view of the table (table_task_view.cpp) and its job search
/// (table_task_move.cpp). Metres.

namespace orthoflow::manipulation {

/// Perceived objects this near the tool are cut by the hand's own body filter.
inline constexpr double HAND_HIDES_M = 0.17;
/// Planned paths keep this much more than the manager's clearance when they can.
inline constexpr double PLAN_MARGIN_M = 0.02;
/// The lowest lift a job is planned with (the grasp check wants the object half of it up).
inline constexpr double LOWEST_LIFT_M = 0.10;
/// From the place on, an object this near the move's spot is the target, put down.
inline constexpr double PLACED_NEAR_M = 0.06;
/// After a move, its object seen this near (along the table) to where it was planned from was left
/// behind.
inline constexpr double LEFT_BEHIND_M = 0.04;

}  // namespace orthoflow::manipulation
