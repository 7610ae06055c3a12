// The robot-body filter (graphs/nodes/body_filter_node.hpp): the arm rendered into simulated Kinect
// frames at 20 reaching poses is removed before segmentation and the rest of the scene is kept;
// frames without a fresh, sane arm state are dropped and counted; a frame held in an IPC chunk is
// copied before it is written; the factory's errors.
#include <gtest/gtest.h>

#include <atomic>
#include <cmath>
#include <cstring>
#include <limits>
#include <random>
#include <thread>
#include <utility>
#include <vector>

#include "core/rng.hpp"
#include "drivers/jaco/jaco_kinematics.hpp"
#include "engine/frame_payload.hpp"
#include "engine/ipc_frame_ref.hpp"
#include "engine/node.hpp"
#include "engine/registry.hpp"
#include "graphs/embedded_graphs.hpp"
#include "graphs/frame/frame_block.hpp"
#include "graphs/nodes/body_filter_node.hpp"
#include "graphs/nodes/segment_params.hpp"
#include "kernels/segmentation_chain.hpp"
#include "manipulation/arm_body.hpp"
#include "manipulation/robot_frames.hpp"
#include "memory_pool/block_pool.hpp"
#include "simulation/world/synthetic_scene.hpp"

namespace orthoflow::graphs {
namespace {

using Eigen::AngleAxisd;
using Eigen::Isometry3d;
using Eigen::Matrix3d;
using Eigen::Vector3d;

constexpr const char* FRAMES_FILE = ORTHOFLOW_SOURCE_DIR "/config/robot_frames_synthetic.yaml";
constexpr std::int64_t T0 = 1'000'000'000'000;  // the frames' and the states' clock, ns

/// Collects what a node emits.
struct Collector final : engine::Emitter {
  std::vector<engine::Message> messages;
  void emit(std::size_t /*port*/, const engine::Message& m) noexcept override {
    messages.push_back(m);
  }
};

/// A body_filter node on its own pool, reading @p slot.
struct Rig {
  explicit Rig(ArmStateChannel& channel, engine::ParamMap params = {}) {
    auto created = memory_pool::BlockPool::create_owned({FrameBlock::bytes_for(640 * 480), 2});
    EXPECT_TRUE(created);
    pool = std::move(*created);
    add_body_filter_node(registry, &channel);
    if (!params.has("robot_frames")) params.assign("robot_frames", FRAMES_FILE);
    if (!params.has("state")) params.assign("state", "channel");
    engine::NodeContext context{"body", pool.get(), 1, engine::BuildMode::RUN};
    auto made = (*registry.find("body_filter"))(params, context);
    EXPECT_TRUE(made) << (made ? "" : made.error());
    if (made) node = std::move(*made);
  }
  /// The filtered frame (or a tombstone) of @p cloud stamped @p stamp_ns.
  engine::Message run(const kernels::PointCloud& cloud) {
    auto block = pool->acquire("test", FrameBlock::bytes_for(cloud.size()));
    EXPECT_TRUE(block);
    const FrameBlock fb(block->bytes(), FrameBlock::capacity_for(block->bytes().size()));
    new (&fb.state()) FrameState{};
    EXPECT_TRUE(engine::write_frame(fb.raw(), cloud));
    engine::Message in;
    in.stamp_ns = cloud.info.host_stamp_ns;
    in.payload = std::move(*block);
    Collector out;
    node->process(in, out);
    EXPECT_EQ(out.messages.size(), 1U);
    return out.messages.empty() ? engine::Message{} : out.messages.front();
  }
  std::uint64_t counter(const char* name) const {
    std::array<engine::DeviceCounter, engine::MAX_DEVICE_COUNTERS> c{};
    const std::size_t n = node->device_counters(c);
    for (std::size_t i = 0; i < n; ++i)
      if (std::string_view(c[i].name) == name) return c[i].value;
    ADD_FAILURE() << "no counter " << name;
    return 0;
  }
  std::unique_ptr<memory_pool::BlockPool> pool;
  engine::NodeRegistry registry;
  std::unique_ptr<engine::Node> node;
};

engine::ArmStatePayload state_at(const drivers::jaco::JointAngles& q, std::int64_t stamp_ns) {
  engine::ArmStatePayload s;
  s.reset();
  s.stamp_ns = stamp_ns;
  for (std::size_t j = 0; j < q.size(); ++j) s.joints_deg[j] = q[j];
  return s;
}

Isometry3d base_from_camera() {
  auto frames = manipulation::load_robot_frames(FRAMES_FILE);
  EXPECT_TRUE(frames) << frames.error();
  return frames->base_from_camera;
}

/// The arm's physical body (the link model without its margin) in the sensor frame.
std::vector<simulation::BodyCapsule> arm_in_view(const drivers::jaco::JointAngles& q) {
  manipulation::ArmBodyModel body;
  body.margin_m = 0.0;
  std::array<kernels::Capsule, manipulation::ARM_BODY_CAPSULES> caps{};
  const std::size_t n = manipulation::arm_body_capsules(q, base_from_camera(), body,
                                                        drivers::jaco::jaco2_geometry(), caps);
  std::vector<simulation::BodyCapsule> out;
  for (std::size_t i = 0; i < n; ++i)
    out.push_back({{caps[i].a[0], caps[i].a[1], caps[i].a[2]},
                   {caps[i].b[0], caps[i].b[1], caps[i].b[2]},
                   caps[i].radius});
  return out;
}

/// Joints that put the gripper, pointing down, @p up above table point (@p x, @p y), if the arm
/// reaches it.
std::optional<drivers::jaco::JointAngles> reach(const simulation::TableSpec& table, double x,
                                                double y, double up, double yaw) {
  const simulation::TableFrame t = simulation::table_frame(table);
  const auto p = t.point(x, y, up);
  Matrix3d camera_rot;  // the tool's z axis (its approach) along -normal
  const Vector3d n(t.normal[0], t.normal[1], t.normal[2]);
  const Vector3d r(t.right[0], t.right[1], t.right[2]);
  const Vector3d zt = -n;
  const Vector3d xt = AngleAxisd(yaw, zt) * r;
  camera_rot.col(0) = xt;
  camera_rot.col(1) = zt.cross(xt);
  camera_rot.col(2) = zt;
  Isometry3d camera_from_tool = Isometry3d::Identity();
  camera_from_tool.linear() = camera_rot;
  camera_from_tool.translation() = Vector3d(p[0], p[1], p[2]);
  const Isometry3d target = base_from_camera() * camera_from_tool;
  auto q = drivers::jaco::inverse_kinematics(target, drivers::jaco::HOME_JOINTS,
                                             drivers::jaco::jaco_joint_limits());
  if (!q) return std::nullopt;
  return *q;
}

kernels::PointCloud render(const simulation::Scene& scene, std::uint64_t seed,
                           std::int64_t stamp_ns) {
  core::Rng rng(seed);
  kernels::PointCloud cloud;
  simulation::render_scene(scene, simulation::RenderOptions{}, rng, cloud);
  cloud.info.host_stamp_ns = stamp_ns;
  return cloud;
}

/// Candidates of the tabletop graph's segmentation whose points are mostly the robot's (label
/// LABEL_ROBOT), and the largest robot share of any candidate.
struct ArmAsObjects {
  int mostly_robot = 0;
  double worst_share = 0.0;
};

ArmAsObjects segment(kernels::SegmentationChain& chain, const engine::FrameView& frame) {
  ArmAsObjects out;
  auto result = chain.run(frame.cloud);
  if (!result) return out;
  std::vector<std::size_t> robot(result->candidates.size(), 0), all(result->candidates.size(), 0);
  for (std::size_t i = 0; i < result->labels.size(); ++i) {
    const std::int32_t cluster = result->labels[i];
    if (cluster < 0) continue;
    const std::int32_t c = result->candidate_of[static_cast<std::size_t>(cluster)];
    if (c < 0) continue;
    ++all[static_cast<std::size_t>(c)];
    robot[static_cast<std::size_t>(c)] += frame.label[i] == simulation::LABEL_ROBOT ? 1U : 0U;
  }
  for (std::size_t c = 0; c < all.size(); ++c) {
    if (all[c] == 0) continue;
    const double share = double(robot[c]) / double(all[c]);
    out.worst_share = std::max(out.worst_share, share);
    out.mostly_robot += share > 0.5 ? 1 : 0;
  }
  return out;
}

kernels::SegmentationChain tabletop_chain() {
  auto spec = engine::parse_graph(std::string(embedded_tabletop_yaml()), "embedded");
  EXPECT_TRUE(spec);
  auto seg = segmentation_of_graph(*spec);
  EXPECT_TRUE(seg) << seg.error();
  return kernels::SegmentationChain(640 * 480, seg->stages, seg->candidates);
}

// The test: the arm at 20 poses reaching over a table with objects, rendered into the
// simulated Kinect's depth. Unfiltered, segmentation takes the arm for objects; filtered by the
// arm's streamed joints, it finds no candidate made of the arm, every arm point is gone, and
// little else is.
TEST(BodyFilter, TheArmAt20PosesIsRemovedBeforeSegmentation) {
  ArmStateChannel channel;
  Rig rig(channel);
  ASSERT_TRUE(rig.node);
  kernels::SegmentationChain chain = tabletop_chain();
  std::mt19937_64 draw(21);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  int poses = 0, unfiltered_arm_objects = 0, filtered_arm_objects = 0, attempts = 0;
  std::size_t robot_points = 0, robot_removed = 0, other_points = 0, other_removed = 0;
  double worst_filtered_share = 0.0;
  while (poses < 20 && attempts < 400) {
    ++attempts;
    simulation::SceneConfig config;
    config.objects = 4;
    simulation::Scene scene = simulation::make_scene(config, 100 + attempts);
    const auto q = reach(scene.table, -0.4 + 0.8 * unit(draw), -0.3 + 0.6 * unit(draw),
                         0.05 + 0.2 * unit(draw), 6.3 * unit(draw));
    if (!q) continue;
    scene.robot = arm_in_view(*q);
    const std::int64_t stamp = T0 + std::int64_t{attempts} * 1'000'000'000;  // a pose a second
    const kernels::PointCloud cloud = render(scene, 7 + attempts, stamp);
    std::size_t in_view = 0;
    for (std::uint32_t l : cloud.label()) in_view += l == simulation::LABEL_ROBOT ? 1U : 0U;
    if (in_view < 500) continue;  // the arm must be in view for the pose to count
    ++poses;
    // Unfiltered: the same frame straight into segmentation.
    {
      auto block = rig.pool->acquire("raw", FrameBlock::bytes_for(cloud.size()));
      ASSERT_TRUE(block);
      ASSERT_TRUE(engine::write_frame(block->bytes(), cloud));
      auto view = engine::view_frame(block->bytes());
      ASSERT_TRUE(view);
      unfiltered_arm_objects += segment(chain, *view).mostly_robot;
    }
    // The arm's stream around the frame (100 Hz): the pose held, 8 ms before and 2 ms after it.
    channel.write(state_at(*q, stamp - 8'000'000));
    channel.write(state_at(*q, stamp + 2'000'000));
    const engine::Message out = rig.run(cloud);
    ASSERT_FALSE(out.skipped);
    const FrameBlock fb(out.payload.bytes(), FrameBlock::capacity_for(out.payload.bytes().size()));
    auto frame = fb.frame();
    ASSERT_TRUE(frame);
    for (std::size_t i = 0; i < cloud.size(); ++i) {
      if (!std::isfinite(cloud.z()[i])) continue;
      const bool robot = cloud.label()[i] == simulation::LABEL_ROBOT;
      const bool removed = std::isnan(frame->cloud.points.z[i]);
      (robot ? robot_points : other_points) += 1;
      (robot ? robot_removed : other_removed) += removed ? 1U : 0U;
      if (!removed) {  // a kept point is untouched
        ASSERT_EQ(frame->cloud.points.x[i], cloud.x()[i]);
        ASSERT_EQ(frame->cloud.points.z[i], cloud.z()[i]);
      }
    }
    const ArmAsObjects seen = segment(chain, *frame);
    filtered_arm_objects += seen.mostly_robot;
    worst_filtered_share = std::max(worst_filtered_share, seen.worst_share);
  }
  ASSERT_EQ(poses, 20) << "reachable poses with the arm in view, of " << attempts;
  const double recall = double(robot_removed) / double(robot_points);
  const double collateral = double(other_removed) / double(other_points);
  std::printf(
      "body filter, 20 poses: %zu arm points, %.4f removed; %zu other points, %.4f "
      "removed; arm objects unfiltered %d, filtered %d (worst arm share in a candidate "
      "%.3f)\n",
      robot_points, recall, other_points, collateral, unfiltered_arm_objects, filtered_arm_objects,
      worst_filtered_share);
  EXPECT_GE(unfiltered_arm_objects, 10) << "the control: unfiltered, the arm is segmented";
  EXPECT_EQ(filtered_arm_objects, 0);
  EXPECT_LT(worst_filtered_share, 0.05);
  EXPECT_GE(recall, 0.995);
  EXPECT_LT(collateral, 0.02);
  EXPECT_EQ(rig.counter("frames_filtered"), 20U);
  EXPECT_EQ(rig.counter("points_removed"), robot_removed + other_removed);
}

kernels::PointCloud small_frame() {
  kernels::PointCloud cloud;
  cloud.resize(8, 4);
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    cloud.x()[i] = 0.01F * float(i % 8);
    cloud.y()[i] = 0.01F * float(i / 8);
    cloud.z()[i] = 1.0F;
  }
  cloud.info.host_stamp_ns = T0;
  return cloud;
}

/// small_frame() whose point 5 is the tool point of the arm at HOME, in the camera frame.
kernels::PointCloud frame_with_the_hand_at_home() {
  const Eigen::Vector3d tool =
      base_from_camera().inverse() *
      drivers::jaco::forward_kinematics(drivers::jaco::HOME_JOINTS).translation();
  kernels::PointCloud cloud = small_frame();
  cloud.x()[5] = float(tool.x());
  cloud.y()[5] = float(tool.y());
  cloud.z()[5] = float(tool.z());
  return cloud;
}

TEST(BodyFilter, FramesWithoutAFreshSaneStateAreDroppedAndCounted) {
  const kernels::PointCloud cloud = small_frame();  // stamped T0
  engine::ParamMap params;
  params.assign("max_state_age_ms", "40");
  // Each case on a fresh filter: the states it has seen, then the frame's verdict.
  const auto verdict = [&](std::vector<engine::ArmStatePayload> states, const char* counter) {
    ArmStateChannel channel;
    Rig rig(channel, params);
    for (const auto& s : states) channel.write(s);
    const engine::Message out = rig.run(cloud);
    EXPECT_EQ(rig.counter(counter), 1U) << counter;
    EXPECT_EQ(rig.counter("states_received"), states.size());
    EXPECT_EQ(out.skipped, !out.payload) << "a tombstone carries no block; a filtered frame does";
    return out.skipped;  // the message (and its block) goes before the rig's pool
  };
  const auto home = [](std::int64_t stamp) { return state_at(drivers::jaco::HOME_JOINTS, stamp); };
  EXPECT_TRUE(verdict({}, "dropped_no_state")) << "no state yet";
  EXPECT_TRUE(verdict({home(T0 - 41'000'000)}, "dropped_stale_state")) << "41 ms old";
  EXPECT_TRUE(verdict({home(T0 + 41'000'000)}, "dropped_stale_state"))
      << "41 ms newer than the frame: not its state either";
  EXPECT_TRUE(verdict({home(T0 - 60'000'000), home(T0 + 60'000'000)}, "dropped_stale_state"))
      << "around the frame, but each too far from it";
  auto fault = home(T0 - 1'000'000);
  fault.flags = engine::ARM_FAULT;
  EXPECT_TRUE(verdict({home(T0 - 30'000'000), fault}, "dropped_arm_fault"));
  auto nan = home(T0 + 1'000'000);
  nan.joints_deg[3] = std::nan("");
  EXPECT_TRUE(verdict({nan}, "dropped_bad_state"));
  // Stamps from another process can be anything: the extremes are stale, never an overflow.
  EXPECT_TRUE(verdict({home(std::numeric_limits<std::int64_t>::min()),
                       home(std::numeric_limits<std::int64_t>::max())},
                      "dropped_stale_state"));
  auto estop = home(T0 - 39'000'000);
  estop.flags = engine::ARM_ESTOP;  // stopped, but its joints are known: the frame is filtered
  EXPECT_FALSE(verdict({estop}, "frames_filtered"));
}

TEST(BodyFilter, TheArmIsLookedUpAtTheFramesTime) {
  // The hand's point at HOME, then the arm swings its base joint 90 degrees away: the frame taken
  // at HOME's time loses the point even though newer states have arrived since.
  kernels::PointCloud cloud = frame_with_the_hand_at_home();
  drivers::jaco::JointAngles away = drivers::jaco::HOME_JOINTS;
  away[0] += 90.0;
  for (const bool swung : {false, true}) {
    ArmStateChannel channel;
    Rig rig(channel);
    for (int k = -3; k <= 3; ++k) {  // states every 10 ms; the frame at k = 0
      const bool at_home = swung ? k <= 0 : k > 0;
      channel.write(
          state_at(at_home ? drivers::jaco::HOME_JOINTS : away, T0 + std::int64_t{k} * 10'000'000));
    }
    const engine::Message out = rig.run(cloud);
    ASSERT_FALSE(out.skipped);
    const FrameBlock fb(out.payload.bytes(), FrameBlock::capacity_for(out.payload.bytes().size()));
    auto frame = fb.frame();
    ASSERT_TRUE(frame);
    EXPECT_EQ(std::isnan(frame->cloud.points.z[5]), swung)
        << (swung ? "at HOME when the frame was taken" : "arrived at HOME only after the frame");
  }
}

TEST(BodyFilter, WhatTheHandHoldsGoesWithTheArm) {
  // Point 6 hangs 25 cm below the hand at HOME, where a held bottle is; point 7 is 10 cm beside it.
  const Eigen::Vector3d tool =
      drivers::jaco::forward_kinematics(drivers::jaco::HOME_JOINTS).translation();
  const Isometry3d camera_from_base = base_from_camera().inverse();
  kernels::PointCloud cloud = small_frame();
  const auto put = [&](std::size_t i, const Eigen::Vector3d& base_point) {
    const Eigen::Vector3d c = camera_from_base * base_point;
    cloud.x()[i] = float(c.x());
    cloud.y()[i] = float(c.y());
    cloud.z()[i] = float(c.z());
  };
  put(6, tool + Vector3d(0.0, 0.0, -0.25));
  put(7, tool + Vector3d(0.10, 0.0, -0.25));
  // What survives with @p held_m in the state: points 6 and 7.
  const auto survivors = [&](const std::array<double, 7>& held_m) {
    ArmStateChannel channel;
    Rig rig(channel);
    engine::ArmStatePayload st = state_at(drivers::jaco::HOME_JOINTS, T0);
    std::copy(held_m.begin(), held_m.end(), st.held_m);
    channel.write(st);
    const engine::Message out = rig.run(cloud);
    EXPECT_FALSE(out.skipped);
    if (out.skipped) return std::pair<bool, bool>{};
    const FrameBlock fb(out.payload.bytes(), FrameBlock::capacity_for(out.payload.bytes().size()));
    auto frame = fb.frame();
    EXPECT_TRUE(frame);
    return std::pair<bool, bool>{!std::isnan(frame->cloud.points.z[6]),
                                 !std::isnan(frame->cloud.points.z[7])};
  };
  const double nan = std::nan("");
  EXPECT_EQ(survivors({}), std::make_pair(true, true)) << "nothing held";
  // A bottle 30 cm tall, 4 cm in radius, hanging from the tool point (plus the 2 cm margin).
  EXPECT_EQ(survivors({0, 0, -0.30, 0, 0, 0, 0.04}), std::make_pair(false, true));
  EXPECT_EQ(survivors({0, 0, -0.30, 0, 0, 0, nan}), std::make_pair(true, true)) << "a bad word";
  EXPECT_EQ(survivors({0, 0, nan, 0, 0, 0, 0.04}), std::make_pair(true, true)) << "a bad word";
  EXPECT_EQ(survivors({0, 0, -0.30, 0, 0, 0, 5.0}), std::make_pair(true, true))
      << "no hand holds it";
}

TEST(BodyFilter, AFrameInAnIpcChunkIsCopiedNotWritten) {
  ArmStateChannel channel;
  Rig rig(channel);
  ASSERT_TRUE(rig.node);
  // The hand, at HOME, inside the frame: a point at the tool point in the camera frame.
  kernels::PointCloud cloud = frame_with_the_hand_at_home();
  std::vector<std::byte> chunk_storage(FrameBlock::bytes_for(cloud.size()) + 64);
  auto* aligned = reinterpret_cast<std::byte*>(
      (reinterpret_cast<std::uintptr_t>(chunk_storage.data()) + 63) & ~std::uintptr_t{63});
  const std::span<std::byte> chunk(aligned, chunk_storage.size() - 64);
  auto written = engine::write_frame(chunk, cloud);
  ASSERT_TRUE(written);
  const std::vector<std::byte> before(chunk.begin(), chunk.begin() + *written);
  auto block = rig.pool->acquire("ipc", sizeof(engine::FrameRef));
  ASSERT_TRUE(block);
  engine::FrameRef ref;
  ref.data = chunk.data();
  ref.size = *written;
  std::memcpy(block->bytes().data(), &ref, sizeof ref);
  channel.write(state_at(drivers::jaco::HOME_JOINTS, T0));
  engine::Message in;
  in.stamp_ns = T0;
  in.payload = std::move(*block);
  Collector out;
  rig.node->process(in, out);
  ASSERT_EQ(out.messages.size(), 1U);
  ASSERT_FALSE(out.messages[0].skipped);
  const FrameBlock fb(out.messages[0].payload.bytes(),
                      FrameBlock::capacity_for(out.messages[0].payload.bytes().size()));
  EXPECT_FALSE(fb.external()) << "the frame now lives in the block";
  auto frame = fb.frame();
  ASSERT_TRUE(frame);
  EXPECT_TRUE(std::isnan(frame->cloud.points.z[5])) << "the hand's point is removed";
  EXPECT_EQ(frame->cloud.points.z[4], 1.0F);
  EXPECT_EQ(frame->header->frame_id, cloud.info.frame_id);
  EXPECT_TRUE(std::equal(before.begin(), before.end(), chunk.begin())) << "the chunk is untouched";
}

TEST(ArmStateChannel, KeepsTheLastDepthWritesInOrder) {
  ArmStateChannel channel;
  std::array<engine::ArmStatePayload, 100> out{};
  EXPECT_EQ(channel.drain(out), 0U);
  for (int k = 0; k < 100; ++k) channel.write(state_at(drivers::jaco::HOME_JOINTS, k));
  const std::size_t n = channel.drain(out);
  ASSERT_EQ(n, ArmStateChannel::DEPTH);
  for (std::size_t i = 0; i < n; ++i) EXPECT_EQ(out[i].stamp_ns, std::int64_t(100 - n + i));
  EXPECT_EQ(channel.drain(out), 0U) << "drained";
  channel.write(state_at(drivers::jaco::HOME_JOINTS, 100));
  channel.write(state_at(drivers::jaco::HOME_JOINTS, 101));
  EXPECT_EQ(channel.drain(std::span(out).first(1)), 1U) << "more than fit: the newest";
  EXPECT_EQ(out[0].stamp_ns, 101);
}

TEST(ArmStateChannel, AConcurrentReaderNeverSeesATornState) {
  ArmStateChannel channel;
  std::atomic<bool> done{false};
  std::thread writer([&] {
    for (int k = 1; k <= 200000; ++k) {
      engine::ArmStatePayload s = state_at(drivers::jaco::HOME_JOINTS, k);
      for (double& q : s.joints_deg) q = k;
      channel.write(s);
    }
    done.store(true);
  });
  std::array<engine::ArmStatePayload, 16> out{};
  std::int64_t last = 0;
  std::size_t seen = 0;
  bool torn = false, backwards = false;
  while (!done.load() || seen == 0) {
    const std::size_t n = channel.drain(out);
    for (std::size_t i = 0; i < n; ++i) {
      for (double q : out[i].joints_deg) torn |= q != double(out[i].stamp_ns);
      backwards |= out[i].stamp_ns <= last;
      last = out[i].stamp_ns;
    }
    seen += n;
  }
  writer.join();
  EXPECT_FALSE(torn);
  EXPECT_FALSE(backwards);
  EXPECT_GT(seen, 0U);
}

TEST(BodyFilter, InstructorZonesRemoveTheirPointsWithoutAnArm) {
  engine::ParamMap params;
  params.assign("arm", "none");
  // Two zones: a sphere of 2 cm around (0.03, 0.01, 1) and a bar along x at y = 0.03.
  params.assign("exclude", "0.03,0.01,1,0.03,0.01,1,0.02; 0,0.03,1, 0.07,0.03,1, 0.001");
  params.assign("robot_frames", "");  // overwritten below: arm none takes none
  engine::ParamMap zones_only;
  zones_only.assign("arm", "none");
  zones_only.assign("exclude", "0.03,0.01,1,0.03,0.01,1,0.02; 0,0.03,1, 0.07,0.03,1, 0.001");
  ArmStateChannel channel;
  auto pool = memory_pool::BlockPool::create_owned({FrameBlock::bytes_for(640 * 480), 2});
  ASSERT_TRUE(pool);
  engine::NodeRegistry registry;
  add_body_filter_node(registry, &channel);
  const engine::NodeContext context{"body", pool->get(), 1, engine::BuildMode::RUN};
  EXPECT_FALSE((*registry.find("body_filter"))(params, context)) << "robot_frames with arm none";
  auto made = (*registry.find("body_filter"))(zones_only, context);
  ASSERT_TRUE(made) << made.error();
  const kernels::PointCloud cloud = small_frame();  // x = 0.01 * column, y = 0.01 * row, z = 1
  auto block = (*pool)->acquire("test", FrameBlock::bytes_for(cloud.size()));
  ASSERT_TRUE(block);
  const FrameBlock fb(block->bytes(), FrameBlock::capacity_for(block->bytes().size()));
  ASSERT_TRUE(engine::write_frame(fb.raw(), cloud));
  engine::Message in;
  in.stamp_ns = T0;
  in.payload = std::move(*block);
  Collector out;
  (*made)->process(in, out);
  ASSERT_EQ(out.messages.size(), 1U);
  EXPECT_FALSE(out.messages[0].skipped) << "no arm: no state needed";
  auto frame = fb.frame();
  ASSERT_TRUE(frame);
  std::size_t removed = 0;
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    const float x = cloud.x()[i], y = cloud.y()[i];
    const bool in_sphere = std::hypot(x - 0.03F, y - 0.01F) <= 0.02F + 1e-6F;
    const bool on_bar = std::fabs(y - 0.03F) <= 0.001F && x <= 0.07F + 1e-6F;
    EXPECT_EQ(std::isnan(frame->cloud.points.z[i]), in_sphere || on_bar) << "point " << i;
    removed += std::isnan(frame->cloud.points.z[i]) ? 1U : 0U;
  }
  EXPECT_GT(removed, 5U);
  out.messages.clear();
}

TEST(BodyFilter, TheFactoryNamesWhatIsWrong) {
  ArmStateChannel channel;
  auto pool = memory_pool::BlockPool::create_owned({FrameBlock::bytes_for(640 * 480), 1});
  ASSERT_TRUE(pool);
  const engine::NodeContext context{"body", pool->get(), 1, engine::BuildMode::CHECK};
  const auto error_of = [&](ArmStateFeed* feed,
                            std::vector<std::pair<std::string, std::string>> kv) {
    engine::NodeRegistry registry;
    add_body_filter_node(registry, feed);
    engine::ParamMap params;
    for (auto& [k, v] : kv) params.assign(k, v);
    auto made = (*registry.find("body_filter"))(params, context);
    return made ? std::string() : made.error();
  };
  EXPECT_NE(error_of(&channel, {}).find("robot_frames"), std::string::npos);
  EXPECT_NE(error_of(&channel, {{"robot_frames", "/nonexistent.yaml"}}).find("/nonexistent.yaml"),
            std::string::npos);
  EXPECT_NE(
      error_of(nullptr, {{"robot_frames", FRAMES_FILE}, {"state", "channel"}}).find("channel"),
      std::string::npos);
  EXPECT_NE(error_of(&channel, {{"robot_frames", FRAMES_FILE}, {"state_topic", "a/b"}})
                .find("state_topic"),
            std::string::npos);
  EXPECT_NE(error_of(&channel, {{"robot_frames", FRAMES_FILE}, {"max_state_age_ms", "0"}})
                .find("max_state_age_ms"),
            std::string::npos);
  EXPECT_NE(error_of(&channel, {{"robot_frames", FRAMES_FILE}, {"colour", "red"}}).find("colour"),
            std::string::npos);
  EXPECT_NE(error_of(&channel, {{"arm", "none"}}).find("exclude"), std::string::npos);
  EXPECT_NE(error_of(&channel, {{"arm", "none"}, {"exclude", "0,0,1,0,0,1"}}).find("7 numbers"),
            std::string::npos);
  EXPECT_NE(
      error_of(&channel, {{"arm", "none"}, {"exclude", "0,0,1,0,0,1,0.1,5"}}).find("more than"),
      std::string::npos);
  EXPECT_NE(error_of(&channel, {{"arm", "none"}, {"exclude", "0,0,1,0,0,1,-1"}}).find("radius"),
            std::string::npos);
  EXPECT_NE(error_of(&channel, {{"arm", "none"}, {"exclude", "0,0,nan,0,0,1,1"}}).find("7 numbers"),
            std::string::npos);
  EXPECT_NE(error_of(&channel, {{"arm", "none"},
                                {"exclude",
                                 "0,0,1,0,0,1,1;0,0,1,0,0,1,1;0,0,1,0,0,1,1;0,0,1,0,0,1,1;"
                                 "0,0,1,0,0,1,1;0,0,1,0,0,1,1;0,0,1,0,0,1,1;0,0,1,0,0,1,1;"
                                 "0,0,1,0,0,1,1"}})
                .find("at most 8"),
            std::string::npos);
  EXPECT_EQ(error_of(&channel, {{"robot_frames", FRAMES_FILE}, {"state", "channel"}}), "");
  EXPECT_EQ(error_of(nullptr, {{"robot_frames", FRAMES_FILE}}), "")
      << "ipc, CHECK: connects nothing";
}

TEST(BodyFilter, InsertedBetweenTheSourceAndPreprocess) {
  auto spec = engine::parse_graph(std::string(embedded_tabletop_yaml()), "embedded");
  ASSERT_TRUE(spec);
  engine::ParamMap params;
  params.assign("robot_frames", FRAMES_FILE);
  ASSERT_TRUE(insert_body_filter(*spec, params));
  bool source_to_body = false, body_to_preprocess = false, source_to_preprocess = false;
  for (const auto& e : spec->edges) {
    source_to_body |= e.from_node == "source" && e.to_node == "body";
    body_to_preprocess |= e.from_node == "body" && e.to_node == "preprocess";
    source_to_preprocess |= e.from_node == "source" && e.to_node == "preprocess";
  }
  EXPECT_TRUE(source_to_body && body_to_preprocess && !source_to_preprocess);
  EXPECT_FALSE(insert_body_filter(*spec, params)) << "a second one is refused";
}

}  // namespace
}  // namespace orthoflow::graphs
