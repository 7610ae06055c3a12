// The table kind (graphs/nodes/segment_nodes.hpp): the table stage's plane (kernels::TableStage),
// then the table verdict (kernels/table_verdict.hpp) with the frame's "up" (its sensor's, else the
// configured camera pose's, else none), then a short hysteresis: when a frame's plane fails, the
// last accepted table is kept for up to hold_frames frames (a hand passing in front of the table).
// Only an accepted or held table sets table_found; the objects node segments nothing without one.
#include <algorithm>
#include <array>
#include <new>

#include "graphs/nodes/node_support.hpp"
#include "graphs/nodes/plane_quality.hpp"
#include "graphs/nodes/segment_nodes.hpp"
#include "graphs/nodes/segment_params.hpp"

namespace orthoflow::graphs {

namespace {

using engine::Emitter;
using engine::Message;
using kernels::TableReason;

const engine::PortSpec TABLE_PORTS[] = {FRAME_IN, FRAME_OUT};

class Table final : public engine::Node {
 public:
  Table(std::size_t capacity, std::string name, const TabletopSegmentation& settings)
      : capacity_(capacity),
        name_(std::move(name)),
        params_(settings.stages),
        table_(settings.table),
        stage_(capacity) {}
  std::span<const engine::PortSpec> inputs() const noexcept override { return {TABLE_PORTS, 1}; }
  std::span<const engine::PortSpec> outputs() const noexcept override {
    return {TABLE_PORTS + 1, 1};
  }
  bool stateful() const noexcept override { return true; }

  void process(const Message& in, Emitter& out) noexcept override {
    const FrameBlock block = block_of(in, capacity_);
    FrameState& s = block.state();
    s.table_found = false;
    s.hull_count = 0;
    s.table_reason = TableReason::NO_PLANE;
    s.judged = kernels::TableJudgement{};
    take_up(block, s);
    if (s.error.empty()) judge(block, s);
    quality_.record_verdict(s.table_reason, s.judged.reason, s.gravity != Gravity::NONE);
    out.emit(0, in);
  }
  const char* counter_group() const noexcept override { return "plane"; }
  std::size_t device_counters(std::span<engine::DeviceCounter> out) const noexcept override {
    return quality_.read(out);
  }

 private:
  /// The frame's own "up" (its sensor's) if it is fresh, else the configured one, else none. A
  /// sensor reading older than max_up_age_ms is refused and its age reported (up_stale_ms).
  void take_up(const FrameBlock& block, FrameState& s) noexcept {
    auto frame = block.frame();
    s.up_stale_ms = 0;
    std::array<float, 3> sensed{};
    if (frame && engine::frame_up(*frame->header, sensed)) {
      if (frame->header->up_age_ms <= table_.max_up_age_ms) {
        s.gravity = Gravity::SENSOR;
        s.up = sensed;
        s.up_age_ms = frame->header->up_age_ms;
        return;
      }
      s.up_stale_ms = std::max<std::uint32_t>(frame->header->up_age_ms, 1);
      quality_.record_stale_up();
    }
    if (table_.up) {
      s.gravity = Gravity::CONFIGURED;
      s.up = *table_.up;
    } else {
      s.gravity = Gravity::NONE;
    }
  }

  void judge(const FrameBlock& block, FrameState& s) noexcept {
    // With an up, RANSAC draws only near-level hypotheses (twice the verdict's angle: three noisy
    // points tilt a hypothesis; the refit plane is what the verdict judges).
    params_.ransac.up = s.gravity == Gravity::NONE ? std::array<float, 3>{} : s.up;
    params_.ransac.max_tilt_deg = std::min(90.0F, 2.0F * table_.verdict.max_tilt_deg);
    auto table = stage_.run(plane_input(block), params_, block.hull_u(), block.hull_v());
    if (table) {
      quality_.record(table->check);
      s.judged = kernels::judge_table(table->plane.plane, table->plane.inliers, s.voxels,
                                      table->hull_u, table->hull_v,
                                      s.gravity == Gravity::NONE ? nullptr : &s.up, table_.verdict);
      if (s.judged.reason == TableReason::ACCEPTED) {
        s.plane = table->plane.plane;
        s.plane_inliers = static_cast<std::uint32_t>(table->plane.inliers);
        s.plane_check = table->check;
        s.hull_count = static_cast<std::uint32_t>(table->hull_u.size());
        s.table_found = true;
        s.table_reason = TableReason::ACCEPTED;
        keep(s, table->hull_u, table->hull_v);
        return;
      }
    } else if (!no_plane(table.error())) {
      s.error.set(name_, table.error());  // the stage failed: the frame's error says why
      return;
    }
    s.table_reason = s.judged.reason;
    if (held_ < table_.hold_frames && kept_hull_ > 0) hold(block, s);
  }

  /// The scene holds no plane (with an up: no near-level one): a verdict, not a failure.
  static bool no_plane(const kernels::SegmentationError& e) noexcept {
    using C = kernels::SegmentationError::Code;
    return e.code == C::NO_PLANE || e.code == C::FEW_SAMPLE_INLIERS || e.code == C::DEGENERATE_HULL;
  }

  /// Remembers an accepted table for the hysteresis.
  void keep(const FrameState& s, std::span<const double> u, std::span<const double> v) noexcept {
    held_ = 0;
    kept_plane_ = s.plane;
    kept_inliers_ = s.plane_inliers;
    kept_check_ = s.plane_check;
    kept_hull_ = std::min(u.size(), MAX_HULL);
    std::copy_n(u.begin(), kept_hull_, kept_u_.begin());
    std::copy_n(v.begin(), kept_hull_, kept_v_.begin());
  }

  /// Puts the last accepted table into this frame.
  void hold(const FrameBlock& block, FrameState& s) noexcept {
    ++held_;
    s.plane = kept_plane_;
    s.plane_inliers = kept_inliers_;
    s.plane_check = kept_check_;
    std::copy_n(kept_u_.begin(), kept_hull_, block.hull_u().begin());
    std::copy_n(kept_v_.begin(), kept_hull_, block.hull_v().begin());
    s.hull_count = static_cast<std::uint32_t>(kept_hull_);
    s.table_found = true;
    s.table_reason = TableReason::HELD;
  }

  std::size_t capacity_;
  std::string name_;
  kernels::SegmentationParams params_;
  TableSettings table_;
  kernels::TableStage stage_;
  PlaneQualityCounters quality_;
  std::uint32_t held_ = 0;
  std::size_t kept_hull_ = 0;  // 0: no table accepted yet
  kernels::Plane kept_plane_{};
  std::uint32_t kept_inliers_ = 0;
  kernels::PlaneCheck kept_check_{};
  std::array<double, MAX_HULL> kept_u_{}, kept_v_{};
};

}  // namespace

NodeResult make_table_node(const engine::ParamMap& params, const engine::NodeContext& context) {
  auto capacity = frame_capacity(context);
  if (!capacity) return err(capacity.error());
  TabletopSegmentation settings;
  if (auto ok = parse_table_params(params, settings); !ok) return err(ok.error());
  return std::unique_ptr<engine::Node>(new Table(*capacity, std::string(context.name), settings));
}

}  // namespace orthoflow::graphs
