#include "manipulation/table_tasks.hpp"

#include <algorithm>
#include <cmath>

namespace orthoflow::manipulation {

namespace {

Eigen::Vector2d xy(const Eigen::Vector3d& p) { return {p.x(), p.y()}; }

bool listed(const std::vector<std::string>& names, const std::string& label) {
  return std::find(names.begin(), names.end(), label) != names.end();
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

TaskPlan plan_clear_table(std::span<const TableObject> objects, const ClearTableOptions& options) {
  TaskPlan plan;
  std::vector<const TableObject*> to_move;
  std::vector<Eigen::Vector2d> occupied;  // what already stands in the area
  for (const TableObject& o : objects) {
    if (o.label.empty()) {
      plan.stays.push_back({o.track, o.label, StayReason::UNKNOWN});
    } else if (listed(options.table_items, o.label)) {
      plan.stays.push_back({o.track, o.label, StayReason::TABLE_ITEM});
    } else if (options.area.contains(xy(o.centre))) {
      plan.stays.push_back({o.track, o.label, StayReason::IN_PLACE});
      occupied.push_back(xy(o.centre));
    } else {
      to_move.push_back(&o);
    }
  }
  for (const TableObject& o : objects)  // an Unknown object or a table item in the area takes room
    if (o.label.empty() || listed(options.table_items, o.label))
      if (options.area.contains(xy(o.centre))) occupied.push_back(xy(o.centre));
  std::sort(to_move.begin(), to_move.end(), [&](const TableObject* a, const TableObject* b) {
    const double da = (xy(a->centre) - options.arm_base).norm();
    const double db = (xy(b->centre) - options.arm_base).norm();
    return da != db ? da < db : a->track < b->track;
  });
  // The grid's spots, row by row from the area's min corner, each half a spacing in from the edges.
  std::vector<Eigen::Vector2d> spots;
  const double s = options.spacing_m;
  if (s > 0.0) {
    for (double y = options.area.min.y() + s / 2; y <= options.area.max.y() - s / 2 + 1e-9; y += s)
      for (double x = options.area.min.x() + s / 2; x <= options.area.max.x() - s / 2 + 1e-9;
           x += s)
        spots.emplace_back(x, y);
  }
  // A spot is taken when anything stands within three quarters of a spacing of it.
  std::size_t next = 0;
  for (const TableObject* o : to_move) {
    while (next < spots.size() &&
           std::any_of(occupied.begin(), occupied.end(), [&](const Eigen::Vector2d& p) {
             return (p - spots[next]).norm() < 0.75 * s;
           }))
      ++next;
    if (next == spots.size()) {
      plan.stays.push_back({o->track, o->label, StayReason::NO_ROOM});
      continue;
    }
    plan.moves.push_back({o->track, o->label, spots[next]});
    occupied.push_back(spots[next]);
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
