#pragma once
/// @file
/// @brief The thesis's two table tasks (chapter 8) as plans: which recognised objects move where,
/// in which order, from the labels the learner gives. Which joints move them is the pick-and-place
/// job's (pick_place_job.hpp), and the execution manager runs each job.
/// - clear_table: every recognised object except the categories marked as table items goes to the
///   placing area, nearest to the arm's base first: to the next free spot of a roomy grid when it
///   has a spot for every object; else each to the first place its footprint fits, inside the area
///   and a gap clear of every other footprint (packed by footprint).
/// - serve_a_meal: the objects of the named categories, in the order named, go to the user's place,
///   side by side along the table's x axis.
/// An object the learner calls Unknown is never moved (the robot does not know what it is); every
/// object left where it is says why. Deterministic (ties broken by track id).
#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include <Eigen/Geometry>

namespace orthoflow::manipulation {

/// @brief A recognised object on the table, in the arm's base frame.
struct TableObject {
  std::uint32_t track = 0;
  std::string label;  ///< empty: Unknown
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();
  double radius_m = 0.0;  ///< its footprint on the table, a circle (footprint_radius())
};

/// @brief The footprint radius of an object whose upright box has edge lengths @p extents (x, y on
/// the table): half the longer one. Tableware is round, and a round object's box is a square
/// around it; a square box's corners reach 41 % further, a mug's handle a few millimetres: the
/// planner's gap between footprints (ClearTableOptions::gap_m) covers them.
[[nodiscard]] double footprint_radius(const Eigen::Vector3d& extents) noexcept;

/// @brief A circle on the table (base frame x, y).
struct Footprint {
  Eigen::Vector2d centre = Eigen::Vector2d::Zero();
  double radius_m = 0.0;
};

/// @brief One move of a task: the object and where its centre goes (x, y on the table).
struct TaskMove {
  std::uint32_t track = 0;
  std::string label;
  Eigen::Vector2d place = Eigen::Vector2d::Zero();
  double radius_m = 0.0;  ///< the object's footprint, which its place was chosen for
};

/// @brief Why an object stays where it is.
enum class StayReason : std::uint8_t {
  UNKNOWN,        ///< the learner does not know what it is
  TABLE_ITEM,     ///< clear_table: a category marked as a table item
  IN_PLACE,       ///< already in the placing area / at the user's place
  NOT_REQUESTED,  ///< serve_a_meal: not one of the named categories
  NO_ROOM,        ///< no free spot left in the area
};
[[nodiscard]] const char* to_string(StayReason reason) noexcept;

struct TaskStay {
  std::uint32_t track = 0;
  std::string label;
  StayReason reason = StayReason::UNKNOWN;
};

struct TaskPlan {
  std::vector<TaskMove> moves;  ///< in execution order
  std::vector<TaskStay> stays;
  /// clear_table: what stands in the placing area and stays (its room is taken).
  std::vector<Footprint> occupied;
  /// clear_table: the places are packed by footprint (the grid had no spot for every object).
  bool packed = false;
  double gap_m = 0.0;  ///< packed: the room kept between footprints (ClearTableOptions::gap_m)
};

/// @brief A rectangle on the table (base frame x, y; min <= max).
struct TableArea {
  Eigen::Vector2d min = Eigen::Vector2d::Zero();
  Eigen::Vector2d max = Eigen::Vector2d::Zero();
  [[nodiscard]] bool contains(const Eigen::Vector2d& p) const noexcept {
    return (p.array() >= min.array()).all() && (p.array() <= max.array()).all();
  }
};

struct ClearTableOptions {
  TableArea area;                        ///< the placing area
  std::vector<std::string> table_items;  ///< categories that stay (e.g. "plate")
  /// The roomy grid: spots this far apart (and half of it in from the edges), taken when anything
  /// stands within three quarters of it. Used whenever it has a spot for every object to move.
  double spacing_m = 0.15;
  /// Packed: the room between two footprints (the hand opens 2 cm wider than what it holds, and its
  /// fingers are about 1.5 cm thick on either side).
  double gap_m = 0.05;
  /// Packed: places are tried on a grid this fine, row by row (+x) from the area's min corner.
  double step_m = 0.01;
  Eigen::Vector2d arm_base = Eigen::Vector2d::Zero();  ///< "nearest first" is measured from here
};

/// @brief True if @p f lies inside @p area and at least @p gap_m clear of every footprint of
/// @p others. False for a non-finite or negative footprint.
[[nodiscard]] bool fits_in_area(const TableArea& area, const Footprint& f,
                                std::span<const Footprint> others, double gap_m) noexcept;

struct ServeOptions {
  std::vector<std::string> categories;                   ///< what to bring, in this order
  Eigen::Vector2d user_place = Eigen::Vector2d::Zero();  ///< the first object's spot
  double spacing_m = 0.15;                               ///< the next ones along +x, this far apart
  double in_place_m = 0.10;  ///< an object this near a spot is already served
};

[[nodiscard]] TaskPlan plan_clear_table(std::span<const TableObject> objects,
                                        const ClearTableOptions& options);
[[nodiscard]] TaskPlan plan_serve_a_meal(std::span<const TableObject> objects,
                                         const ServeOptions& options);

}  // namespace orthoflow::manipulation
