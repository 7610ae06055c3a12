// The table task's world (graphs/sessions/table_task_session.hpp): the names of the scripted
// events, the manager's limits for the loop, the camera pose the synthetic table implies and the
// seeded table of a task. The loop itself is in table_task_session.cpp.
#include <algorithm>
#include <cmath>
#include <vector>

#include "graphs/sessions/table_task_session.hpp"
#include "manipulation/table_tasks.hpp"
#include "simulation/world/table_world.hpp"

namespace orthoflow::graphs {

namespace jaco = drivers::jaco;
using Eigen::Isometry3d;
using Eigen::Vector2d;
using Eigen::Vector3d;
using manipulation::Phase;

const char* to_string(TaskEvent event) noexcept {
  switch (event) {
    case TaskEvent::MOVE_TARGET:
      return "move-target";
    case TaskEvent::STOP_PERCEPTION:
      return "stop-perception";
    case TaskEvent::UNPLUG_ARM:
      return "unplug-arm";
    default:
      return "none";
  }
}

manipulation::ExecutionLimits TableTaskConfig::default_limits() noexcept {
  manipulation::ExecutionLimits limits;
  limits.target_lost_ns = 5'000'000'000;
  for (const Phase p : {Phase::APPROACH, Phase::LIFT, Phase::PLACE, Phase::RETREAT})
    limits.timeout_ns[static_cast<std::size_t>(p)] = 20'000'000'000;
  limits.obstacle_clearance_m = 0.02;
  limits.target_moved_m = 0.06;
  return limits;
}

Isometry3d synthetic_base_from_camera(const simulation::TableSpec& table) {
  const simulation::TableFrame t = simulation::table_frame(table);
  constexpr double BASE_BEYOND_CENTRE_M = 0.28284271247461906;  // 0.98995 - 0.70711 (the yaml)
  const auto v = [](const simulation::Vec3& a) { return Vector3d(a[0], a[1], a[2]); };
  Isometry3d camera_from_base = Isometry3d::Identity();
  const Vector3d z = v(t.normal), y = v(t.forward);
  camera_from_base.linear().col(0) = y.cross(z);
  camera_from_base.linear().col(1) = y;
  camera_from_base.linear().col(2) = z;
  camera_from_base.translation() = v(t.point(0.0, BASE_BEYOND_CENTRE_M));
  return camera_from_base.inverse();
}

simulation::Scene draw_task_table(const TableTaskConfig& config, std::uint64_t seed) {
  simulation::SceneConfig scene_config;
  scene_config.objects = std::min<std::uint32_t>(config.objects + 6, simulation::MAX_SCENE_OBJECTS);
  scene_config.categories =
      config.categories.empty()
          ? std::vector<simulation::Category>{simulation::Category::BOTTLE,
                                              simulation::Category::MUG, simulation::Category::CAN,
                                              simulation::Category::FLASK,
                                              simulation::Category::PLATE}
          : config.categories;
  simulation::Scene scene = simulation::make_scene(scene_config, seed);
  scene.table = simulation::TableSpec{};  // the table the robot frames assume
  const Isometry3d base_from_camera = synthetic_base_from_camera(scene.table);
  const simulation::TableFrame frame = simulation::table_frame(scene.table);
  // Keep the objects that stand on this table, clear of the arm's base column, up to the count.
  std::vector<simulation::PlacedObject> kept;
  for (const simulation::PlacedObject& o : scene.objects) {
    const double r = o.model.footprint_radius;
    const bool on_table = std::fabs(o.table_x) + r < 0.5 * scene.table.width_m - 0.02 &&
                          std::fabs(o.table_y) + r < 0.5 * scene.table.depth_m - 0.02;
    const simulation::Vec3 p = frame.point(o.table_x, o.table_y);
    const Vector2d at = (base_from_camera * Vector3d(p[0], p[1], p[2])).head<2>();
    // The placing area and the user's place start empty (a tray, a place setting).
    const Vector2d margin(r + 0.02, r + 0.02);
    const manipulation::TableArea area{config.area.min - margin, config.area.max + margin};
    bool free = true;
    if (config.task == TableTask::CLEAR_TABLE) {
      free = !area.contains(at);
    } else {
      for (std::size_t k = 0; k < std::max<std::size_t>(config.bring.size(), 1); ++k)
        free = free && (at - config.user_place - Vector2d(0.15 * double(k), 0.0)).norm() > r + 0.08;
    }
    if (on_table && free && at.norm() > 0.30 && kept.size() < config.objects) kept.push_back(o);
  }
  scene.objects = std::move(kept);
  for (std::size_t i = 0; i < scene.objects.size(); ++i)
    scene.objects[i].id = static_cast<std::uint32_t>(i);
  return scene;
}

}  // namespace orthoflow::graphs
