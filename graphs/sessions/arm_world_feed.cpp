#include "graphs/sessions/arm_world_feed.hpp"

#include <chrono>
#include <cmath>
#include <utility>

#include "drivers/jaco/jaco_kinematics.hpp"
#include "graphs/sessions/table_task_session.hpp"
#include "manipulation/arm_body.hpp"
#include "manipulation/pick_place_job.hpp"

namespace orthoflow::graphs {

namespace jaco = drivers::jaco;

Result<std::unique_ptr<ArmWorldFeed>, std::string> ArmWorldFeed::create(
    std::uint64_t seed, const std::string& state_topic, std::uint64_t frames) {
  auto states = IpcArmStateFeed::create(state_topic);
  if (!states) return err("world: " + states.error());
  TableTaskConfig config;  // clear_table's table: the placing area starts empty
  return std::unique_ptr<ArmWorldFeed>(
      new ArmWorldFeed(draw_task_table(config, seed), std::move(*states), seed, frames));
}

ArmWorldFeed::ArmWorldFeed(simulation::Scene scene, std::unique_ptr<IpcArmStateFeed> states,
                           std::uint64_t seed, std::uint64_t frames)
    : world_(std::move(scene)),
      states_(std::move(states)),
      base_from_camera_(synthetic_base_from_camera(simulation::TableSpec{})),
      camera_from_base_(base_from_camera_.inverse()),
      rng_(seed ^ 0x5eedULL),
      frames_limit_(frames) {
  for (std::size_t i = 0; i < world_.scene().objects.size(); ++i)
    start_.push_back(world_.centre(i));
  world_.robot().reserve(simulation::MAX_SCENE_CAPSULES);
}

const simulation::Scene* ArmWorldFeed::next_frame(kernels::PointCloud& cloud) noexcept {
  if (frames_limit_ > 0 && frame_ >= frames_limit_) return nullptr;
  // Every state since the last frame, in order: the hand closes, holds, carries, lets go.
  const manipulation::JobOptions fingers;  // the finger-to-opening map the task plans with
  const std::size_t n = states_->drain(drained_);
  for (std::size_t k = 0; k < n; ++k) {
    const engine::ArmStatePayload& s = drained_[k];
    jaco::JointAngles q{};
    bool finite = std::isfinite(s.fingers[0]);
    for (std::size_t j = 0; j < q.size(); ++j) {
      q[j] = s.joints_deg[j];
      finite = finite && std::isfinite(q[j]);
    }
    if (!finite) continue;  // never move the world on a state that is not one
    const Eigen::Vector3d tool = camera_from_base_ * jaco::forward_kinematics(q).translation();
    world_.update({tool.x(), tool.y(), tool.z()},
                  manipulation::opening_for_finger(s.fingers[0], fingers));
    joints_ = q;
    ++applied_;
  }
  // The exposure: the world as it is now, with the arm where its newest state says. Stamped now,
  // before the render (tens of milliseconds): the body filter looks the arm up at this time.
  const std::int64_t now = std::chrono::duration_cast<std::chrono::nanoseconds>(
                               std::chrono::steady_clock::now().time_since_epoch())
                               .count();
  // The arm as the camera sees it: the link model without the filter's margin.
  std::vector<simulation::BodyCapsule>& robot = world_.robot();
  robot.clear();
  if (joints_) {
    std::array<kernels::Capsule, manipulation::ARM_BODY_CAPSULES> capsules{};
    manipulation::ArmBodyModel body;
    body.margin_m = 0.0;
    const std::size_t c = manipulation::arm_body_capsules(*joints_, base_from_camera_, body,
                                                          jaco::jaco2_geometry(), capsules);
    for (std::size_t i = 0; i < c; ++i)
      robot.push_back({{capsules[i].a[0], capsules[i].a[1], capsules[i].a[2]},
                       {capsules[i].b[0], capsules[i].b[1], capsules[i].b[2]},
                       capsules[i].radius});
  }
  simulation::render_scene(world_.scene(), render_, rng_, cloud);
  cloud.info.frame_id = frame_;
  cloud.info.sensor_stamp_ns = now;
  cloud.info.host_stamp_ns = now;
  ++frame_;
  return &world_.scene();
}

WorldTally ArmWorldFeed::tally() const {
  WorldTally t;
  t.objects = world_.scene().objects.size();
  t.fallen = world_.fallen();
  t.frames = frame_;
  t.arm_states = applied_;
  for (std::size_t i = 0; i < t.objects && i < start_.size(); ++i) {
    const Eigen::Vector3d a =
        base_from_camera_ * Eigen::Vector3d(start_[i][0], start_[i][1], start_[i][2]);
    const simulation::Vec3 c = world_.centre(i);
    const Eigen::Vector3d b = base_from_camera_ * Eigen::Vector3d(c[0], c[1], c[2]);
    if ((b - a).head<2>().norm() > 0.05) ++t.moved;
  }
  return t;
}

}  // namespace orthoflow::graphs
