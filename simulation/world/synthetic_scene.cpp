// Scene geometry and random scene layout. The rendering itself is in synthetic_render.cpp.
#include "simulation/world/synthetic_scene.hpp"

#include <algorithm>
#include <cmath>

#include "core/assert.hpp"

namespace orthoflow::simulation {
namespace {

constexpr double PI = 3.14159265358979323846;
constexpr double GAP_M = 0.01;          // clearance between footprints of objects that do not touch
constexpr double EDGE_MARGIN_M = 0.02;  // objects keep this far from the table edges
constexpr int ATTEMPTS_PER_OBJECT = 200;

struct Footprint {
  double x, y, r;
};

bool fits(const Footprint& f, const std::vector<PlacedObject>& placed, double gap) {
  for (const PlacedObject& o : placed) {
    const double need = f.r + o.model.footprint_radius + gap;
    const double dx = f.x - o.table_x, dy = f.y - o.table_y;
    if (dx * dx + dy * dy < need * need * (1.0 - 1e-9)) { return false; }
  }
  return true;
}

bool on_table(const Footprint& f, const TableSpec& t) {
  return std::fabs(f.x) + f.r <= t.width_m / 2 - EDGE_MARGIN_M &&
         std::fabs(f.y) + f.r <= t.depth_m / 2 - EDGE_MARGIN_M;
}

Category pick_category(const SceneConfig& config, core::Rng& rng) {
  if (config.categories.empty()) { return static_cast<Category>(rng.below(SCENE_CATEGORY_COUNT)); }
  return config.categories[rng.below(config.categories.size())];
}

/// A spot for @p model: uniformly on the table, or (touching) on the circle around @p anchor.
bool place(const ObjectModel& model, const Scene& scene, const PlacedObject* anchor, core::Rng& rng,
           PlacedObject& out) {
  const TableSpec& t = scene.table;
  for (int attempt = 0; attempt < ATTEMPTS_PER_OBJECT; ++attempt) {
    Footprint f{0, 0, model.footprint_radius};
    if (anchor != nullptr) {
      const double a = rng.uniform(0.0, 2.0 * PI);
      const double dist = model.footprint_radius + anchor->model.footprint_radius;
      f.x = anchor->table_x + dist * std::cos(a);
      f.y = anchor->table_y + dist * std::sin(a);
    } else {
      f.x = rng.uniform(-t.width_m / 2, t.width_m / 2);
      f.y = rng.uniform(-t.depth_m / 2, t.depth_m / 2);
    }
    if (!on_table(f, t) || !fits(f, scene.objects, anchor != nullptr ? 0.0 : GAP_M)) { continue; }
    out = PlacedObject{model, f.x, f.y, rng.uniform(0.0, 2.0 * PI)};
    return true;
  }
  return false;
}

}  // namespace

TableFrame table_frame(const TableSpec& table) noexcept {
  // The camera looks down at the table: the table normal leans towards the sensor (-y is up, -z is
  // towards the sensor). tilt = angle between the optical axis and the table plane.
  const double c = std::cos(table.tilt_rad), s = std::sin(table.tilt_rad);
  TableFrame f;
  f.normal = {0.0, -c, -s};
  f.right = {1.0, 0.0, 0.0};
  f.forward = {0.0, -s, c};
  f.center = {0.0, 0.0, table.distance_m};
  f.d = -dot(f.normal, f.center);
  return f;
}

std::array<double, 16> object_pose(const TableFrame& table, const PlacedObject& object) noexcept {
  const double c = std::cos(object.yaw), s = std::sin(object.yaw);
  const Vec3 ax = c * table.right + s * table.forward;
  const Vec3 ay = (-s) * table.right + c * table.forward;
  const Vec3& az = table.normal;
  const Vec3 p = table.point(object.table_x, object.table_y, object.base_m);
  return {ax[0], ay[0], az[0], p[0], ax[1], ay[1], az[1], p[1],
          ax[2], ay[2], az[2], p[2], 0,     0,     0,     1};
}

std::array<Vec3, 4> table_corners(const TableSpec& table) noexcept {
  const TableFrame f = table_frame(table);
  const double w = table.width_m / 2, d = table.depth_m / 2;
  return {f.point(-w, -d), f.point(w, -d), f.point(w, d), f.point(-w, d)};
}

Scene make_scene(const SceneConfig& config, std::uint64_t seed) {
  OF_ENFORCE(config.objects <= MAX_SCENE_OBJECTS, "make_scene: too many objects");
  OF_ENFORCE(config.instances_per_category > 0, "make_scene: instances_per_category must be > 0");
  core::Rng rng(seed);
  Scene scene;
  scene.table.distance_m = rng.uniform(0.7, 1.2);
  scene.table.tilt_rad = rng.uniform(30.0, 60.0) * PI / 180.0;
  // About as wide as the view at the table centre (58 degrees horizontal field of view), so the
  // side edges show at the far end and the near and far edges show whole; at least 0.9 m so that
  // ten objects usually fit.
  // Two draws in one call would be unsequenced (GCC and clang order arguments differently): one per
  // statement.
  const double view_width = scene.table.distance_m * rng.uniform(0.95, 1.1);
  scene.table.width_m = std::max(view_width, rng.uniform(0.9, 1.0));
  scene.table.depth_m = rng.uniform(0.6, 0.8);
  scene.table.floor_drop_m = config.floor ? rng.uniform(0.65, 0.78) : 0.0;
  std::array<ObjectModel, MAX_SCENE_OBJECTS> models{};
  for (std::uint32_t i = 0; i < config.objects; ++i) {
    const Category category = config.stacked ? Category::BOX : pick_category(config, rng);
    models[i] = make_object_model(
        category, static_cast<std::uint32_t>(rng.below(config.instances_per_category)));
  }
  // Large footprints first: packing them while the table is empty lets more objects fit.
  if (config.stacked) {  // the smaller box of each pair on top
    for (std::uint32_t i = 1; i < config.objects; i += 2) {
      if (models[i].footprint_radius > models[i - 1].footprint_radius) {
        std::swap(models[i], models[i - 1]);
      }
      // The top box fits on the bottom one: the largest box instance at most 0.85 of its size.
      if (models[i].footprint_radius > 0.85 * models[i - 1].footprint_radius) {
        for (std::uint32_t k = 0; k < config.instances_per_category; ++k) {
          const ObjectModel m = make_object_model(Category::BOX, k);
          const bool fits_on = m.footprint_radius <= 0.85 * models[i - 1].footprint_radius;
          if (fits_on && (models[i].footprint_radius > 0.85 * models[i - 1].footprint_radius ||
                          m.footprint_radius > models[i].footprint_radius)) {
            models[i] = m;
          }
        }
      }
    }
  } else if (!config.touching) {
    std::stable_sort(models.begin(), models.begin() + config.objects,
                     [](const ObjectModel& a, const ObjectModel& b) {
                       return a.footprint_radius > b.footprint_radius;
                     });
  }
  scene.objects.reserve(config.objects);
  for (std::uint32_t i = 0; i < config.objects; ++i) {
    PlacedObject placed;
    if (config.stacked && i % 2 == 1) {
      if (scene.objects.empty() || scene.objects.back().base_m > 0.0) continue;  // no support
      const PlacedObject& below = scene.objects.back();
      if (models[i].footprint_radius > 0.85 * below.model.footprint_radius) continue;  // no fit
      const double slack = 0.3 * (below.model.footprint_radius - models[i].footprint_radius);
      const double dx = rng.uniform(-slack, slack);
      const double dy = rng.uniform(-slack, slack);
      placed = PlacedObject{
          models[i], below.table_x + dx, below.table_y + dy, below.yaw + rng.uniform(-0.35, 0.35),
          0,         below.model.height};
      placed.id = static_cast<std::uint32_t>(scene.objects.size());
      scene.objects.push_back(placed);
      continue;
    }
    const bool touch = config.touching && !config.stacked && i % 2 == 1 && !scene.objects.empty();
    const PlacedObject* anchor = touch ? &scene.objects.back() : nullptr;
    if (place(models[i], scene, anchor, rng, placed)) {
      placed.id = static_cast<std::uint32_t>(scene.objects.size());
      scene.objects.push_back(placed);
    }
  }
  return scene;
}

}  // namespace orthoflow::simulation
