// The preprocess, table and objects kinds: scheduling around the stage objects of
// kernels/tabletop_stages.hpp, the same ones kernels::SegmentationChain (and so `orthoflow
// segment`, the benchmarks and the PCL agreement tests) runs. Each node runs one stage on the
// frame's block:
//   preprocess: PlaneInputStage  -> the plane input in voxels() (dense sample, then the sparse one)
//   table:      table_node.cpp   (TableStage, the table verdict and its hysteresis)
//   objects:    objects_node.cpp (ObjectStage and the candidate constraints)
#include "graphs/nodes/segment_nodes.hpp"

#include <new>

#include "graphs/nodes/node_support.hpp"
#include "graphs/nodes/segment_params.hpp"

namespace orthoflow::graphs {

namespace {

using engine::Emitter;
using engine::Message;
using engine::ParamMap;

const engine::PortSpec FRAME_PORTS[] = {FRAME_IN, FRAME_OUT};

/// Base of the frame-in, frame-out kinds: ports, capacity and the node's name for its errors.
class FrameStage : public engine::Node {
 public:
  FrameStage(std::size_t capacity, std::string name)
      : capacity_(capacity), name_(std::move(name)) {}
  std::span<const engine::PortSpec> inputs() const noexcept override { return {FRAME_PORTS, 1}; }
  std::span<const engine::PortSpec> outputs() const noexcept override {
    return {FRAME_PORTS + 1, 1};
  }
  bool stateful() const noexcept override { return true; }

 protected:
  std::size_t capacity_;
  std::string name_;
};

class Preprocess final : public FrameStage {
 public:
  Preprocess(std::size_t capacity, std::string name, const kernels::SegmentationParams& params)
      : FrameStage(capacity, std::move(name)), params_(params), stage_(capacity) {}

  void process(const Message& in, Emitter& out) noexcept override {
    const FrameBlock block = block_of(in, capacity_);
    // Our sources clear the state; a frame that came through IPC (ipc_subscribe) did not meet one.
    if (block.external()) new (&block.state()) FrameState{};
    FrameState& s = block.state();
    s.kept = s.voxels = s.sparse = 0;
    s.roi = params_.roi;
    auto frame = block.frame();
    if (!frame) {
      s.error.set(FrameError::Code::INVALID_FRAME, name_,
                  static_cast<std::uint8_t>(frame.error().code));
      out.emit(0, in);
      return;
    }
    s.organized_path = kernels::takes_organized_path(frame->cloud, params_);
    if (auto input = stage_.run(frame->cloud, params_, block.voxels())) {
      s.kept = static_cast<std::uint32_t>(input->kept);
      s.voxels = static_cast<std::uint32_t>(input->dense.size());
      s.sparse = static_cast<std::uint32_t>(input->sparse.size());
    } else {
      s.error.set(name_, input.error());
    }
    out.emit(0, in);
  }

 private:
  kernels::SegmentationParams params_;
  kernels::PlaneInputStage stage_;
};

NodeResult make_preprocess(const ParamMap& params, const engine::NodeContext& context) {
  auto capacity = frame_capacity(context);
  if (!capacity) return err(capacity.error());
  kernels::SegmentationParams p = TabletopSegmentation::defaults();
  if (auto ok = parse_preprocess_params(params, p); !ok) return err(ok.error());
  return std::unique_ptr<engine::Node>(new Preprocess(*capacity, std::string(context.name), p));
}

}  // namespace

kernels::PlaneInput plane_input(const FrameBlock& block) noexcept {
  const FrameState& s = block.state();
  const kernels::PointsSpan v = block.voxels();
  const auto part = [&](std::size_t offset, std::size_t n) {
    return kernels::PointsView{v.x.subspan(offset, n), v.y.subspan(offset, n),
                               v.z.subspan(offset, n)};
  };
  return kernels::PlaneInput{part(0, s.voxels), part(s.voxels, s.sparse), s.kept};
}

// The table and objects kinds are long enough for their own files (table_node.cpp,
// objects_node.cpp).
NodeResult make_table_node(const ParamMap& params, const engine::NodeContext& context);
NodeResult make_objects_node(const ParamMap& params, const engine::NodeContext& context,
                             LabelsWriter* labels);

void add_segment_nodes(engine::NodeRegistry& registry, LabelsWriter* labels) {
  registry.add(
      "preprocess",
      "plane input: drops NaN and out-of-ROI points, strided pixel sample (organized) or voxel "
      "grid: "
      "roi_min_x..roi_max_z (m), leaf (m, 0 = off), organized_stride (pixels, 0 = voxel grid)",
      make_preprocess);
  registry.add("table",
               "RANSAC table plane + support polygon, then the table verdict: tau (m), "
               "iterations, confidence, seed, max_tilt_deg, min_height, max_height (m), min_share, "
               "min_area (m^2), hold_frames, up (\"x,y,z\" or none)",
               make_table_node);
  registry.add("objects",
               "prism + Euclidean clusters + footprint merge + C_size/C_edge: h_min, h_max, "
               "tolerance, min_points, "
               "max_points, pixel_radius, merge_overlap, min_size, max_size, edge_margin (m)",
               [labels](const ParamMap& params, const engine::NodeContext& context) {
                 return make_objects_node(params, context, labels);
               });
}

}  // namespace orthoflow::graphs
