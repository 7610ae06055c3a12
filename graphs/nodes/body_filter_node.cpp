// The body_filter kind (graphs/nodes/body_filter_node.hpp): the arm's capsules from the newest
// joint state, kernels::capsule_mask over the frame, NaN where the arm is. Its settings are parsed
// in body_filter_settings.cpp, which also puts it into a graph.
#include "graphs/nodes/body_filter_node.hpp"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <limits>
#include <new>
#include <string>
#include <vector>

#include <unistd.h>

#include "engine/ipc_frame_ref.hpp"
#include "engine/ipc_runtime.hpp"
#include "graphs/nodes/body_filter_settings.hpp"
#include "graphs/nodes/node_support.hpp"
#include "manipulation/arm_body.hpp"

namespace orthoflow::graphs {

namespace {

using engine::Emitter;
using engine::Message;
using engine::ParamMap;

const engine::PortSpec PORTS[] = {FRAME_IN, FRAME_OUT};

/// A held object wider than this is a bad word, not an object a JACO hand holds.
constexpr double MAX_HELD_RADIUS_M = 0.3;

/// |a - b| for every pair of stamps (a state or a frame from another process may carry any value).
std::uint64_t distance_ns(std::int64_t a, std::int64_t b) noexcept {
  return a > b ? static_cast<std::uint64_t>(a) - static_cast<std::uint64_t>(b)
               : static_cast<std::uint64_t>(b) - static_cast<std::uint64_t>(a);
}

/// Why a frame was not filtered.
enum class Verdict { FILTERED, NO_STATE, STALE, FAULT, BAD_STATE, TOO_LARGE };

class BodyFilter final : public engine::Node {
 public:
  BodyFilter(std::size_t capacity, const BodyFilterSettings& settings, ArmStateFeed* feed,
             std::unique_ptr<ArmStateFeed> owned)
      : capacity_(capacity),
        settings_(settings),
        feed_(owned ? owned.get() : feed),
        owned_(std::move(owned)),
        mask_(capacity) {}

  std::span<const engine::PortSpec> inputs() const noexcept override { return {PORTS, 1}; }
  std::span<const engine::PortSpec> outputs() const noexcept override { return {PORTS + 1, 1}; }
  bool stateful() const noexcept override { return true; }

  void process(const Message& in, Emitter& out) noexcept override {
    const FrameBlock block = block_of(in, capacity_);
    const Verdict verdict = filter(block, in.stamp_ns);
    count(verdict);
    if (verdict == Verdict::FILTERED) {
      out.emit(0, in);
      return;
    }
    Message tomb = in;
    tomb.skipped = true;
    tomb.payload.reset();
    out.emit(0, tomb);
  }

  const char* counter_group() const noexcept override { return "body"; }
  std::size_t device_counters(std::span<engine::DeviceCounter> out) const noexcept override {
    const engine::DeviceCounter all[] = {
        {"frames_filtered", filtered_.load(std::memory_order_relaxed)},
        {"points_removed", removed_.load(std::memory_order_relaxed)},
        {"last_points_removed", last_removed_.load(std::memory_order_relaxed)},
        {"dropped_no_state", no_state_.load(std::memory_order_relaxed)},
        {"dropped_stale_state", stale_.load(std::memory_order_relaxed)},
        {"dropped_arm_fault", fault_.load(std::memory_order_relaxed)},
        {"dropped_bad_state", bad_.load(std::memory_order_relaxed)},
        {"dropped_too_large", too_large_.load(std::memory_order_relaxed)},
        {"last_state_age_us", last_age_us_.load(std::memory_order_relaxed)},
        {"states_received", feed_ != nullptr ? feed_->received() : 0},
        {"states_rejected", feed_ != nullptr ? feed_->rejected() : 0},
    };
    const std::size_t n = std::min(out.size(), std::size(all));
    for (std::size_t i = 0; i < n; ++i) out[i] = all[i];
    return n;
  }

 private:
  /// The frame held in an iceoryx chunk, copied into the block so that it can be written. False
  /// if it does not fit (more points than the pool's blocks hold): the frame is dropped.
  bool localise(const FrameBlock& block) noexcept {
    const std::span<const std::byte> bytes = engine::resolve_frame_bytes(block.raw());
    if (bytes.size() > block.raw().size()) return false;
    std::memmove(block.raw().data(), bytes.data(), bytes.size());
    new (&block.state()) FrameState{};  // what preprocess does for an IPC frame: it met no source
    return true;
  }

  Verdict filter(const FrameBlock& block, std::int64_t message_stamp_ns) noexcept {
    if (block.external() && !localise(block)) return Verdict::TOO_LARGE;
    auto frame = block.frame();
    if (!frame) return Verdict::FILTERED;  // not a frame: preprocess reports INVALID_FRAME
    const std::int64_t frame_ns =
        frame->header->host_stamp_ns != 0 ? frame->header->host_stamp_ns : message_stamp_ns;
    std::array<kernels::Capsule, manipulation::ARM_BODY_CAPSULES + MAX_ZONES> capsules{};
    std::size_t count = 0;
    if (settings_.arm) {
      drivers::jaco::JointAngles joints{};
      manipulation::HeldObject held;
      if (const Verdict v = joints_at(frame_ns, joints, held); v != Verdict::FILTERED) return v;
      count = manipulation::arm_body_capsules(
          joints, settings_.base_from_camera, settings_.model, *settings_.geometry,
          std::span<kernels::Capsule, manipulation::ARM_BODY_CAPSULES>(
              capsules.data(), manipulation::ARM_BODY_CAPSULES),
          held);
    }
    for (std::size_t z = 0; z < settings_.zone_count; ++z) capsules[count++] = settings_.zones[z];
    const kernels::CloudView& cloud = frame->cloud;
    const std::size_t n = cloud.points.size();
    if (n > mask_.size()) return Verdict::TOO_LARGE;
    const std::span<std::uint8_t> mask = std::span<std::uint8_t>(mask_).first(n);
    const std::size_t removed = kernels::capsule_mask(
        cloud.points, std::span<const kernels::Capsule>(capsules.data(), count), mask);
    if (removed > 0) {
      // The block is this frame's own (localised above), so its points are writable.
      float* x = const_cast<float*>(
          cloud.points.x.data());  // NOLINT(cppcoreguidelines-pro-type-const-cast)
      float* y = const_cast<float*>(
          cloud.points.y.data());  // NOLINT(cppcoreguidelines-pro-type-const-cast)
      float* z = const_cast<float*>(
          cloud.points.z.data());  // NOLINT(cppcoreguidelines-pro-type-const-cast)
      const float nan = std::numeric_limits<float>::quiet_NaN();
      for (std::size_t i = 0; i < n; ++i) {
        if (mask[i] == 0) x[i] = y[i] = z[i] = nan;
      }
    }
    removed_.fetch_add(removed, std::memory_order_relaxed);
    last_removed_.store(removed, std::memory_order_relaxed);
    return Verdict::FILTERED;
  }

  /// Takes the states that arrived into the history (a ring of the last HISTORY).
  void take_states() noexcept {
    if (feed_ == nullptr) return;
    const std::size_t n = feed_->drain(incoming_);
    for (std::size_t i = 0; i < n; ++i) { history_[(history_next_ + i) % HISTORY] = incoming_[i]; }
    history_next_ = (history_next_ + n) % HISTORY;
    history_count_ = std::min(HISTORY, history_count_ + n);
  }

  /// The arm's joints at @p frame_ns: between the two states around it (linearly, when both lie
  /// within the age limit), else the nearest state's, if it is no further than the limit.
  Verdict joints_at(std::int64_t frame_ns, drivers::jaco::JointAngles& joints,
                    manipulation::HeldObject& held) noexcept {
    take_states();
    if (history_count_ == 0) return Verdict::NO_STATE;
    const engine::ArmStatePayload* before = nullptr;  // newest at or before the frame
    const engine::ArmStatePayload* after = nullptr;   // oldest after it
    const engine::ArmStatePayload* nearest = nullptr;
    std::uint64_t nearest_age = std::numeric_limits<std::uint64_t>::max();
    for (std::size_t i = 0; i < history_count_; ++i) {
      const engine::ArmStatePayload& s = history_[i];
      const std::uint64_t age = distance_ns(s.stamp_ns, frame_ns);
      if (age < nearest_age) nearest_age = age, nearest = &s;
      if (s.stamp_ns <= frame_ns && (before == nullptr || s.stamp_ns > before->stamp_ns))
        before = &s;
      if (s.stamp_ns > frame_ns && (after == nullptr || s.stamp_ns < after->stamp_ns)) after = &s;
    }
    last_age_us_.store(nearest_age / 1000, std::memory_order_relaxed);
    const auto max_age = static_cast<std::uint64_t>(settings_.max_state_age_ns);
    if (nearest_age > max_age) return Verdict::STALE;
    // Both within the limit of the frame: their differences below cannot overflow.
    const bool bracket = before != nullptr && after != nullptr &&
                         distance_ns(frame_ns, before->stamp_ns) <= max_age &&
                         distance_ns(after->stamp_ns, frame_ns) <= max_age;
    for (const engine::ArmStatePayload* s :
         {nearest, bracket ? before : nearest, bracket ? after : nearest}) {
      if ((s->flags & engine::ARM_FAULT) != 0) return Verdict::FAULT;
      for (double q : s->joints_deg)
        if (!std::isfinite(q)) return Verdict::BAD_STATE;
    }
    const double w = bracket ? static_cast<double>(frame_ns - before->stamp_ns) /
                                   static_cast<double>(after->stamp_ns - before->stamp_ns)
                             : 0.0;
    for (std::size_t j = 0; j < joints.size(); ++j) {
      const double a = bracket ? before->joints_deg[j] : nearest->joints_deg[j];
      const double b = bracket ? after->joints_deg[j] : a;
      // 10 ms apart, a joint moves a few degrees at most: a larger step is a wrap of a continuous
      // joint's reading, or a jump; the nearer sample is the safer one then.
      joints[j] = std::fabs(b - a) <= 30.0 ? a + w * (b - a) : nearest->joints_deg[j];
    }
    // What the hand holds: the nearest state's word (a capsule that is not finite is no capsule).
    const double* h = nearest->held_m;
    if (std::isfinite(h[6]) && h[6] > 0.0 && h[6] < MAX_HELD_RADIUS_M &&
        std::all_of(h, h + 6, [](double v) { return std::isfinite(v) && std::fabs(v) < 1.0; })) {
      held.a = Eigen::Vector3d(h[0], h[1], h[2]);
      held.b = Eigen::Vector3d(h[3], h[4], h[5]);
      held.radius_m = h[6];
    }
    return Verdict::FILTERED;
  }

  void count(Verdict v) noexcept {
    switch (v) {
      case Verdict::FILTERED:
        filtered_.fetch_add(1, std::memory_order_relaxed);
        return;
      case Verdict::TOO_LARGE:
        too_large_.fetch_add(1, std::memory_order_relaxed);
        return;
      case Verdict::NO_STATE:
        no_state_.fetch_add(1, std::memory_order_relaxed);
        return;
      case Verdict::STALE:
        stale_.fetch_add(1, std::memory_order_relaxed);
        return;
      case Verdict::FAULT:
        fault_.fetch_add(1, std::memory_order_relaxed);
        return;
      case Verdict::BAD_STATE:
        bad_.fetch_add(1, std::memory_order_relaxed);
        return;
    }
  }

  std::size_t capacity_;
  BodyFilterSettings settings_;
  ArmStateFeed* feed_;
  std::unique_ptr<ArmStateFeed> owned_;
  std::vector<std::uint8_t> mask_;            // sized once: the pool's frame capacity
  static constexpr std::size_t HISTORY = 64;  // 640 ms of states at 100 Hz
  std::array<engine::ArmStatePayload, HISTORY> history_{};
  std::array<engine::ArmStatePayload, HISTORY> incoming_{};
  std::size_t history_next_ = 0;
  std::size_t history_count_ = 0;
  std::atomic<std::uint64_t> filtered_{0}, removed_{0}, last_removed_{0};
  std::atomic<std::uint64_t> no_state_{0}, stale_{0}, fault_{0}, bad_{0}, too_large_{0};
  std::atomic<std::uint64_t> last_age_us_{0};
};

NodeResult make_body_filter(const ParamMap& params, const engine::NodeContext& context,
                            ArmStateFeed* channel) {
  auto capacity = frame_capacity(context);
  if (!capacity) return err(capacity.error());
  auto settings = parse_body_filter_settings(params);
  if (!settings) return err(settings.error());
  auto state = params.choice("state", "ipc", {"ipc", "channel"});
  if (!state) return err(state.error());
  auto topic = params.text("state_topic", engine::ARM_STATE_TOPIC);
  if (!topic) return err(topic.error());
  if (auto parsed = engine::parse_topic(*topic); !parsed)
    return err("body_filter: state_topic: " + engine::to_string(parsed.error()));
  if (*state == "channel") {
    if (channel == nullptr)
      return err(
          std::string("body_filter: state channel needs an arm in this process (none was given); "
                      "use state: ipc"));
    return std::unique_ptr<engine::Node>(new BodyFilter(*capacity, *settings, channel, nullptr));
  }
  std::unique_ptr<ArmStateFeed> feed;
  if (context.mode == engine::BuildMode::RUN && settings->arm) {
    if (auto init = engine::init_ipc_runtime("orthoflow_" + std::to_string(::getpid())); !init)
      return err("body_filter: " + engine::to_string(init.error()));
    auto created = IpcArmStateFeed::create(*topic);
    if (!created) return err("body_filter: " + created.error());
    feed = std::move(*created);
  }
  return std::unique_ptr<engine::Node>(
      new BodyFilter(*capacity, *settings, nullptr, std::move(feed)));
}

}  // namespace

void add_body_filter_node(engine::NodeRegistry& registry, ArmStateFeed* channel) {
  registry.add("body_filter",
               "robot-body filter (C_robot): points inside the arm's link model become NaN; "
               "robot_frames (file) or base_from_camera (tx,ty,tz,qw,qx,qy,qz), state (ipc | "
               "channel), state_topic, max_state_age_ms, margin (m), "
               "arm (jaco2 | jaco_v1 | none), exclude (instructor zones: ax,ay,az,bx,by,bz,r;...); "
               "frames without a fresh arm state are dropped and counted",
               [channel](const ParamMap& params, const engine::NodeContext& context) {
                 return make_body_filter(params, context, channel);
               });
}

}  // namespace orthoflow::graphs
