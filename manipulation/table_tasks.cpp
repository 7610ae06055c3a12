#include "manipulation/table_tasks.hpp"

#include <algorithm>
#include <cmath>
#include <optional>

namespace orthoflow::manipulation {

namespace {

Eigen::Vector2d xy(const Eigen::Vector3d& p) { return {p.x(), p.y()}; }

bool listed(const std::vector<std::string>& names, const std::string& label) {
  return std::find(names.begin(), names.end(), label) != names.end();
}

Footprint footprint(const TableObject& o) {
  return Footprint{xy(o.centre), std::max(o.radius_m, 0.0)};
}

// The grid's spots, row by row from the area's min corner, each half a spacing in from the edges; a
// spot is taken when anything stands within three quarters of a spacing of it. Every object's move
// to the next free spot, or nullopt when the spots run out first.
std::optional<std::vector<TaskMove>> grid_places(std::span<const TableObject* const> to_move,
                                                 std::span<const Footprint> occupied,
                                                 const ClearTableOptions& options) {
  std::vector<Eigen::Vector2d> spots;
  const double s = options.spacing_m;
  if (!(s > 0.0) || !std::isfinite(s)) return std::nullopt;
  const Eigen::Vector2d size = options.area.max - options.area.min;
  if (!size.allFinite() || (size.array() < s).any()) return std::nullopt;
  for (double y = options.area.min.y() + s / 2; y <= options.area.max.y() - s / 2 + 1e-9; y += s)
    for (double x = options.area.min.x() + s / 2; x <= options.area.max.x() - s / 2 + 1e-9; x += s)
      spots.emplace_back(x, y);
  std::vector<Eigen::Vector2d> standing;
  for (const Footprint& f : occupied) standing.push_back(f.centre);
  std::vector<TaskMove> moves;
  std::size_t next = 0;
  for (const TableObject* o : to_move) {
    while (next < spots.size() &&
           std::any_of(standing.begin(), standing.end(), [&](const Eigen::Vector2d& p) {
             return (p - spots[next]).norm() < 0.75 * s;
           }))
      ++next;
    if (next == spots.size()) return std::nullopt;
    moves.push_back({o->track, o->label, spots[next], footprint(*o).radius_m});
    standing.push_back(spots[next]);
  }
  return moves;
}

}  // namespace

const char* to_string(StayReason reason) noexcept {
  switch (reason) {
    case StayReason::UNKNOWN:
      return "unknown";
    case StayReason::TABLE_ITEM:
      return "table_item";
    case StayReason::IN_PLACE:
      return "in_place";
    case StayReason::NOT_REQUESTED:
      return "not_requested";
    case StayReason::NO_ROOM:
      return "no_room";
  }
  return "unknown";
}

double footprint_radius(const Eigen::Vector3d& extents) noexcept {
  return 0.5 * std::max(extents.x(), extents.y());
}

bool fits_in_area(const TableArea& area, const Footprint& f, std::span<const Footprint> others,
                  double gap_m) noexcept {
  constexpr double SLACK = 1e-9;  // a place exactly at the limit fits
  if (!f.centre.allFinite() || !std::isfinite(f.radius_m) || f.radius_m < 0.0) return false;
  const Eigen::Array2d r = Eigen::Array2d::Constant(f.radius_m);
  if ((f.centre.array() - r < area.min.array() - SLACK).any() ||
      (f.centre.array() + r > area.max.array() + SLACK).any())
    return false;
  return std::none_of(others.begin(), others.end(), [&](const Footprint& o) {
    return (o.centre - f.centre).norm() < o.radius_m + f.radius_m + gap_m - SLACK;
  });
}

TaskPlan plan_clear_table(std::span<const TableObject> objects, const ClearTableOptions& options) {
  TaskPlan plan;
  std::vector<const TableObject*> to_move;
  for (const TableObject& o : objects) {
    const bool in_area = options.area.contains(xy(o.centre));
    if (o.label.empty()) {
      plan.stays.push_back({o.track, o.label, StayReason::UNKNOWN});
    } else if (listed(options.table_items, o.label)) {
      plan.stays.push_back({o.track, o.label, StayReason::TABLE_ITEM});
    } else if (in_area) {
      plan.stays.push_back({o.track, o.label, StayReason::IN_PLACE});
    } else {
      to_move.push_back(&o);
      continue;
    }
    if (in_area) plan.occupied.push_back(footprint(o));  // whatever stands in the area takes room
  }
  std::sort(to_move.begin(), to_move.end(), [&](const TableObject* a, const TableObject* b) {
    const double da = (xy(a->centre) - options.arm_base).norm();
    const double db = (xy(b->centre) - options.arm_base).norm();
    return da != db ? da < db : a->track < b->track;
  });
  // The roomy grid first (every spot a spacing from the next, whatever the objects); packed by
  // footprint only when the grid has no spot for every object.
  if (auto spots = grid_places(to_move, plan.occupied, options)) {
    plan.moves = std::move(*spots);
    return plan;
  }
  plan.packed = true;
  plan.gap_m = options.gap_m;
  // Each object's place: the first of a fine grid, row by row (+x) from the area's min corner,
  // where its footprint fits beside everything that stands there or was given a place before it.
  // At most 1000 places along a side: a bounded search whatever the options.
  const Eigen::Vector2d size = options.area.max - options.area.min;
  const bool grid = options.step_m > 0.0 && std::isfinite(options.step_m) && size.allFinite() &&
                    (size.array() >= 0).all();
  const double step = grid ? std::max(options.step_m, size.maxCoeff() / 1000.0) : 0.0;
  const long columns = grid ? static_cast<long>(std::floor(size.x() / step)) + 1 : 0;
  const long rows = grid ? static_cast<long>(std::floor(size.y() / step)) + 1 : 0;
  std::vector<Footprint> taken = plan.occupied;
  for (const TableObject* o : to_move) {
    Footprint f = footprint(*o);
    bool found = false;
    for (long j = 0; j < rows && !found; ++j) {
      for (long i = 0; i < columns && !found; ++i) {
        f.centre = options.area.min + Eigen::Vector2d(double(i) * step, double(j) * step);
        found = fits_in_area(options.area, f, taken, options.gap_m);
      }
    }
    if (!found) {
      plan.stays.push_back({o->track, o->label, StayReason::NO_ROOM});
      continue;
    }
    plan.moves.push_back({o->track, o->label, f.centre, f.radius_m});
    taken.push_back(f);
  }
  return plan;
}

TaskPlan plan_serve_a_meal(std::span<const TableObject> objects, const ServeOptions& options) {
  TaskPlan plan;
  std::vector<bool> taken(objects.size(), false);
  std::size_t spot = 0;
  const auto spot_at = [&](std::size_t k) {
    return Eigen::Vector2d(options.user_place.x() + options.spacing_m * double(k),
                           options.user_place.y());
  };
  for (const std::string& category : options.categories) {
    // The nearest object of the category to the user's place that is not there yet.
    const TableObject* best = nullptr;
    std::size_t best_index = 0;
    for (std::size_t i = 0; i < objects.size(); ++i) {
      const TableObject& o = objects[i];
      if (taken[i] || o.label != category) continue;
      const double d = (xy(o.centre) - options.user_place).norm();
      if (best == nullptr || d < (xy(best->centre) - options.user_place).norm() ||
          (d == (xy(best->centre) - options.user_place).norm() && o.track < best->track)) {
        best = &o;
        best_index = i;
      }
    }
    if (best == nullptr) continue;  // nothing of that category on the table
    taken[best_index] = true;
    if ((xy(best->centre) - spot_at(spot)).norm() <= options.in_place_m) {
      plan.stays.push_back({best->track, best->label, StayReason::IN_PLACE});
    } else {
      plan.moves.push_back({best->track, best->label, spot_at(spot)});
    }
    ++spot;
  }
  for (std::size_t i = 0; i < objects.size(); ++i) {
    if (taken[i]) continue;
    plan.stays.push_back(
        {objects[i].track, objects[i].label,
         objects[i].label.empty() ? StayReason::UNKNOWN : StayReason::NOT_REQUESTED});
  }
  return plan;
}

}  // namespace orthoflow::manipulation
