#pragma once
/// @file
/// @brief (internal) FrameSource: the base of the graph's frame sources (source_nodes.cpp,
/// kinect_source.cpp): one output port, a pool block per frame, the cloud written in place.
#include <algorithm>
#include <new>
#include <span>
#include <string_view>

#include "engine/frame_payload.hpp"
#include "engine/node.hpp"
#include "graphs/frame/frame_block.hpp"
#include "graphs/nodes/decode_ahead.hpp"
#include "graphs/nodes/node_support.hpp"
#include "kernels/point_cloud.hpp"
#include "simulation/world/object_catalog.hpp"
#include "simulation/world/synthetic_scene.hpp"

namespace orthoflow::graphs {

inline const engine::PortSpec SOURCE_OUT[] = {FRAME_OUT};

/// Base of the sources: one output port, capacity, the block of each frame. Pacing is the engine's
/// (the graph period); a source produces as soon as it is asked.
class FrameSource : public engine::Node {
 public:
  FrameSource(std::size_t capacity, const engine::NodeContext& context)
      : capacity_(capacity), pool_(context.pool), name_(context.name) {}
  std::span<const engine::PortSpec> inputs() const noexcept override { return {}; }
  std::span<const engine::PortSpec> outputs() const noexcept override { return SOURCE_OUT; }
  bool stateful() const noexcept override { return true; }
  void process(const engine::Message& /*in*/, engine::Emitter& /*out*/) noexcept override {}

 protected:
  /// Takes a pool block for the next frame; false (frame skipped, counted by the engine as a source
  /// drop) if the pool is exhausted.
  bool take_block(engine::Message& out) noexcept {
    auto block = pool_->acquire(name_, pool_->block_bytes());
    if (!block) {
      out.skipped = true;
      return false;
    }
    out.payload = std::move(*block);
    return true;
  }
  /// The ground truth of a synthetic frame: each object's label and category.
  void write_truth(engine::Message& out,
                   std::span<const simulation::PlacedObject> objects) const noexcept {
    FrameState& s = block_of(out, capacity_).state();
    s.truth_count = static_cast<std::uint32_t>(std::min(objects.size(), MAX_TRUTH));
    for (std::uint32_t k = 0; k < s.truth_count; ++k) {
      s.truth[k].label = simulation::OBJECT_LABEL_BASE + objects[k].id;
      s.truth[k].category.assign(simulation::category_name(objects[k].model.category));
    }
  }
  /// A simulated camera knows its pose: "up" is the simulated table's normal (the table is level).
  static void take_up(kernels::PointCloud& cloud, const simulation::TableSpec& table) noexcept {
    const auto n = simulation::table_frame(table).normal;
    cloud.info.up = {static_cast<float>(n[0]), static_cast<float>(n[1]), static_cast<float>(n[2])};
    cloud.info.up_age_ms = 0;
  }
  /// A file that could not be used (@p slot's error, or no slot within the decoder's timeout,
  /// @p timeout_text): an empty frame carrying the error, so the run counts and names it.
  void emit_decode_failure(engine::Message& out, const DecodeAhead::Slot* slot,
                           std::string_view timeout_text) noexcept {
    const FrameBlock block = block_of(out, capacity_);
    (void)engine::write_frame(block.raw(), kernels::PointCloud{});
    new (&block.state()) FrameState{};
    FrameError& e = block.state().error;
    e.set(FrameError::Code::FILE_UNREADABLE, name_,
          slot == nullptr ? 0 : static_cast<std::uint8_t>(slot->error.code));
    e.detail.assign_elided(slot == nullptr ? timeout_text : std::string_view(slot->error.message));
  }
  /// Writes @p cloud into the message's block and clears the per-frame state.
  bool emit_cloud(engine::Message& out, const kernels::PointCloud& cloud) noexcept {
    const FrameBlock block = block_of(out, capacity_);
    new (&block.state()) FrameState{};  // value-initialised in place: no temporary on the stack
    if (cloud.size() > capacity_ || !engine::write_frame(block.raw(), cloud)) {
      block.state().error.set(FrameError::Code::FRAME_TOO_LARGE, name_, 0,
                              static_cast<double>(cloud.size()));
      return false;
    }
    return true;
  }
  std::size_t capacity_;
  memory_pool::BlockPool* pool_;
  std::string_view name_;
};

}  // namespace orthoflow::graphs
