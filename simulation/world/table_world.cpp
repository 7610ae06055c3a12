#include "simulation/world/table_world.hpp"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <utility>

namespace orthoflow::simulation {

namespace {

/// @p p in table coordinates: x along the table's right, y along its forward, up along its normal.
Vec3 to_table(const TableFrame& t, const Vec3& p) noexcept {
  const Vec3 d = p - t.center;
  return {dot(d, t.right), dot(d, t.forward), dot(d, t.normal)};
}

}  // namespace

TableWorld::TableWorld(Scene scene) : scene_(std::move(scene)), frame_(table_frame(scene_.table)) {}

int TableWorld::find(std::uint32_t id) const noexcept {
  for (std::size_t i = 0; i < scene_.objects.size(); ++i) {
    if (scene_.objects[i].id == id) return static_cast<int>(i);
  }
  return -1;
}

Vec3 TableWorld::centre(std::size_t index) const noexcept {
  const PlacedObject& o = scene_.objects[index];
  return frame_.point(o.table_x, o.table_y, o.base_m + 0.5 * o.model.height);
}

bool TableWorld::inside(const PlacedObject& o, const Vec3& local) const noexcept {
  const double dx = local[0] - o.table_x;
  const double dy = local[1] - o.table_y;
  const double r = o.model.footprint_radius + GRIP_SLACK_M;
  return dx * dx + dy * dy <= r * r && local[2] >= o.base_m - GRIP_SLACK_M &&
         local[2] <= o.base_m + o.model.height + GRIP_SLACK_M;
}

void TableWorld::update(const Vec3& tool, double opening_m) noexcept {
  const Vec3 local = to_table(frame_, tool);
  // The first call is no motion (NaN compares false).
  const bool closing = opening_m < last_opening_ - 1e-4;
  const bool opening = opening_m > last_opening_ + 1e-4;
  last_opening_ = opening_m;
  if (held_ >= 0) {
    if (opening && opening_m > grip_opening_ + RELEASE_MARGIN_M) {
      release();
      return;
    }
    grip_opening_ = std::min(grip_opening_, opening_m);  // the fingers squeeze it
    PlacedObject& o = scene_.objects[static_cast<std::size_t>(held_)];
    o.table_x = local[0] + grip_offset_[0];
    o.table_y = local[1] + grip_offset_[1];
    o.base_m = std::max(0.0, local[2] + grip_offset_[2]);
    return;
  }
  if (!closing) return;
  // Closing fingers hold the nearest object whose cylinder holds the tool point, once they are
  // narrower than its footprint.
  int best = -1;
  double best_d2 = 0.0;
  for (std::size_t i = 0; i < scene_.objects.size(); ++i) {
    const PlacedObject& o = scene_.objects[i];
    if (opening_m >= 2.0 * o.model.footprint_radius || !inside(o, local)) continue;
    const double dx = local[0] - o.table_x, dy = local[1] - o.table_y;
    if (best < 0 || dx * dx + dy * dy < best_d2) {
      best = static_cast<int>(i);
      best_d2 = dx * dx + dy * dy;
    }
  }
  if (best < 0) return;
  held_ = best;
  grip_opening_ = opening_m;
  const PlacedObject& o = scene_.objects[static_cast<std::size_t>(best)];
  grip_offset_ = {o.table_x - local[0], o.table_y - local[1], o.base_m - local[2]};
}

void TableWorld::release() noexcept {
  const auto index = static_cast<std::size_t>(held_);
  held_ = -1;
  PlacedObject& o = scene_.objects[index];
  const double half_w = 0.5 * scene_.table.width_m, half_d = 0.5 * scene_.table.depth_m;
  if (std::fabs(o.table_x) > half_w || std::fabs(o.table_y) > half_d) {
    scene_.objects.erase(scene_.objects.begin() + static_cast<std::ptrdiff_t>(index));
    ++fallen_;
    return;
  }
  o.base_m = 0.0;
}

bool TableWorld::move_object(std::size_t index, double x, double y) noexcept {
  if (index >= scene_.objects.size() || static_cast<int>(index) == held_) return false;
  scene_.objects[index].table_x = x;
  scene_.objects[index].table_y = y;
  return true;
}

}  // namespace orthoflow::simulation
