#include "graphs/nodes/track_describe_nodes.hpp"

#include <algorithm>
#include <atomic>
#include <memory>
#include <thread>
#include <vector>

#include "graphs/nodes/descriptor_params.hpp"
#include "graphs/nodes/node_support.hpp"
#include "graphs/nodes/tracker.hpp"
#include "kernels/descriptor_spec.hpp"

namespace orthoflow::graphs {

namespace {

using engine::Emitter;
using engine::Message;
using engine::ParamMap;

const engine::PortSpec TRACK_PORTS[] = {FRAME_IN, OBJECT_OUT};
const engine::PortSpec DESCRIBE_PORTS[] = {OBJECT_IN, OBJECT_OUT};

class Track final : public engine::Node {
 public:
  Track(std::size_t capacity, const TrackerParams& params)
      : capacity_(capacity), tracker_(params), inputs_(MAX_OBJECTS), outputs_(MAX_OBJECTS) {}
  std::span<const engine::PortSpec> inputs() const noexcept override { return {TRACK_PORTS, 1}; }
  std::span<const engine::PortSpec> outputs() const noexcept override {
    return {TRACK_PORTS + 1, 1};
  }
  bool stateful() const noexcept override { return true; }

  void process(const Message& in, Emitter& out) noexcept override {
    const FrameBlock block = block_of(in, capacity_);
    FrameState& s = block.state();
    const std::size_t n = s.object_count;
    for (std::size_t k = 0; k < n; ++k) {
      const kernels::ClusterStats& st = s.objects[k].stats;
      inputs_[k] = TrackInput{block.object_view(k), st.centroid, st.bbox_min, st.bbox_max};
    }
    auto frame = block.frame();
    const std::int64_t stamp = frame ? frame->header->sensor_stamp_ns : in.stamp_ns;
    tracker_.update(stamp, std::span<const TrackInput>(inputs_).first(n), outputs_);
    for (std::size_t k = 0; k < n; ++k) {
      ObjectRecord& o = s.objects[k];
      o.track_id = outputs_[k].track_id;
      o.new_track = outputs_[k].new_track;
      o.moving = outputs_[k].moving;
      o.key_view = outputs_[k].key_view;
      o.fragment = outputs_[k].fragment;
    }
    // One message per object (one empty message when there is none, so the join still sees the
    // frame).
    Message object = in;
    object.object_count = static_cast<std::uint32_t>(n);
    for (std::uint32_t k = 0; k < (n == 0 ? 1U : n); ++k) {
      object.object_index = k;
      out.emit(0, object);
    }
  }

 private:
  std::size_t capacity_;
  Tracker tracker_;
  std::vector<TrackInput> inputs_;
  std::vector<TrackOutput> outputs_;
};

/// The scratches of describing over a dictionary (spin features; LDA: words and topic counts):
/// one per call that can run at once (the arena's threads), each reserved once for
/// max_object_points, taken and given back lock-free.
class FeaturePool {
 public:
  FeaturePool(std::size_t count, std::size_t max_points, const kernels::DescriptorSpec& spec)
      : scratch_(count), busy_(count) {
    for (auto& s : scratch_) s.reserve(spec, max_points);
    for (auto& b : busy_) b.store(false);
  }
  /// @brief A free scratch, or nullptr when every one is taken (one pass: bounded).
  kernels::WordScratch* take() noexcept {
    for (std::size_t i = 0; i < busy_.size(); ++i) {
      bool expected = false;
      if (busy_[i].compare_exchange_strong(expected, true, std::memory_order_acquire))
        return &scratch_[i];
    }
    return nullptr;
  }
  void give(kernels::WordScratch* s) noexcept {
    busy_[static_cast<std::size_t>(s - scratch_.data())].store(false, std::memory_order_release);
  }

 private:
  std::vector<kernels::WordScratch> scratch_;
  std::vector<std::atomic<bool>> busy_;
};

class Describe final : public engine::Node {
 public:
  Describe(std::size_t capacity, const kernels::DescriptorSpec& spec, std::size_t slots,
           std::size_t max_object_points)
      : capacity_(capacity), describers_(slots * MAX_OBJECTS, kernels::Describer(spec)) {
    if (spec.spin_features()) {  // spin, bow, lda or local-lda: spin features first
      // More scratches than the arena can run at once: hardware threads, and never fewer than 4.
      const std::size_t workers = std::max<std::size_t>(4, std::thread::hardware_concurrency());
      pool_ = std::make_unique<FeaturePool>(workers + 1, max_object_points, spec);
    }
  }
  std::span<const engine::PortSpec> inputs() const noexcept override { return {DESCRIBE_PORTS, 1}; }
  std::span<const engine::PortSpec> outputs() const noexcept override {
    return {DESCRIBE_PORTS + 1, 1};
  }
  bool stateful() const noexcept override { return false; }

  // Runs concurrently for different objects: each (slot, object) has its own describer and its own
  // record and descriptor region in the block, so no two calls touch the same memory; a set of
  // spin images or a bag of words takes a spin-feature scratch of the pool for the call.
  void process(const Message& in, Emitter& out) noexcept override {
    if (in.object_count > 0 && in.object_index < MAX_OBJECTS) {
      const FrameBlock block = block_of(in, capacity_);
      ObjectRecord& o = block.state().objects[in.object_index];
      kernels::Describer& describer = describers_[in.slot * MAX_OBJECTS + in.object_index];
      const auto view = block.object_view(in.object_index);
      const auto room = block.descriptor(in.object_index);
      kernels::WordScratch* features = pool_ ? pool_->take() : nullptr;
      // GOOD, or (more calls at once than hardware threads, e.g. --threads above the cores) the
      // describer's own scratch, which grows: correct, but it may allocate.
      auto described =
          features ? describer.describe(view, room, *features) : describer.describe(view, room);
      if (features) pool_->give(features);
      o.described = described.has_value();
      if (described) {
        o.descriptor_length = static_cast<std::uint32_t>(described->length);
        o.frame = described->frame;
        o.bbox = described->bbox;
        o.good_flags = described->flags;
      }
    }
    out.emit(0, in);
  }

 private:
  std::size_t capacity_;
  std::vector<kernels::Describer> describers_;
  std::unique_ptr<FeaturePool> pool_;  ///< over a dictionary only
};

NodeResult make_track(const ParamMap& params, const engine::NodeContext& context) {
  auto capacity = frame_capacity(context);
  if (!capacity) return err(capacity.error());
  if (auto ok = params.only(
          {"min_share", "box_margin", "lost_timeout_s", "moving_speed", "static_frames"});
      !ok) {
    return err(ok.error());
  }
  TrackerParams p;
  p.max_tracks = MAX_OBJECTS;
  std::string e;
  take(params.number("min_share", p.min_share, 0.01, 1.0), p.min_share, e);
  take(params.number("box_margin", p.box_margin, 0.0, 1.0), p.box_margin, e);
  take(params.number("lost_timeout_s", p.lost_timeout_s, 0.0, 3600.0), p.lost_timeout_s, e);
  take(params.number("moving_speed", p.moving_speed, 0.0, 10.0), p.moving_speed, e);
  take(params.integer("static_frames", p.static_frames, 1, 1000), p.static_frames, e);
  if (!e.empty()) return err(e);
  return std::unique_ptr<engine::Node>(new Track(*capacity, p));
}

NodeResult make_describe(const ParamMap& params, const engine::NodeContext& context) {
  auto capacity = frame_capacity(context);
  if (!capacity) return err(capacity.error());
  auto spec = parse_describe_params(params);
  if (!spec) return err(spec.error());
  auto max_points = parse_max_object_points(params);
  if (!max_points) return err(max_points.error());
  const std::size_t block_bytes = context.pool == nullptr ? 0 : context.pool->block_bytes();
  if (const std::size_t room = FrameBlock::room_in(block_bytes, *capacity); spec->length() > room)
    return err(
        spec->describe() + ": " + std::to_string(spec->length()) +
        " floats per object do not fit the frame block's " + std::to_string(room) +
        " (raise pool block_bytes to " +
        std::to_string(FrameBlock::bytes_for(*capacity, descriptor_room_for(spec->length()))) +
        ")");
  return std::unique_ptr<engine::Node>(
      new Describe(*capacity, *spec, context.max_in_flight, *max_points));
}

}  // namespace

void add_track_describe_nodes(engine::NodeRegistry& registry) {
  registry.add(
      "track",
      "tracks objects by box overlap, splits the frame into objects: min_share, box_margin (m), "
      "lost_timeout_s, moving_speed (m/s), static_frames",
      make_track);
  registry.add("describe",
               "per object, in parallel: descriptor and object frame: descriptor (good, spin, bow, "
               "lda, local-lda), bins, mode, threshold; spin: spin_keypoints, spin_width, "
               "spin_support (m), spin_leaf (m); bow, lda, local-lda: dictionary, local_topics; "
               "max_object_points",
               make_describe);
}

}  // namespace orthoflow::graphs
