#include "graphs/segment_nodes.hpp"

#include <algorithm>
#include <new>
#include <vector>

#include "graphs/node_support.hpp"
#include "kernels/convex_hull.hpp"
#include "kernels/crop.hpp"
#include "kernels/ransac_plane.hpp"
#include "kernels/voxel_grid.hpp"

namespace orthoflow::graphs {

namespace {

using engine::Emitter;
using engine::Message;
using engine::ParamMap;

const engine::PortSpec FRAME_PORTS[] = {FRAME_IN, FRAME_OUT};

/// Base of the frame-in, frame-out kinds: ports and capacity.
class FrameStage : public engine::Node {
 public:
  explicit FrameStage(std::size_t capacity) : capacity_(capacity) {}
  std::span<const engine::PortSpec> inputs() const noexcept override { return {FRAME_PORTS, 1}; }
  std::span<const engine::PortSpec> outputs() const noexcept override { return {FRAME_PORTS + 1, 1}; }
  bool stateful() const noexcept override { return true; }

 protected:
  std::size_t capacity_;
};

class Preprocess final : public FrameStage {
 public:
  Preprocess(std::size_t capacity, kernels::AxisBox roi, float leaf)
      : FrameStage(capacity), roi_(roi), leaf_(leaf), mask_(capacity), kx_(capacity), ky_(capacity), kz_(capacity),
        voxel_scratch_(capacity) {}

  void process(const Message& in, Emitter& out) noexcept override {
    const FrameBlock block = block_of(in, capacity_);
    // Our sources clear the state; a frame that came through IPC (ipc_subscribe) did not meet one.
    if (block.external()) new (&block.state()) FrameState{};
    FrameState& s = block.state();
    auto frame = block.frame();
    if (!frame) {
      s.error.assign("preprocess: the block holds no valid frame");
      out.emit(0, in);
      return;
    }
    const kernels::PointsView points = frame->cloud.points;
    const std::size_t kept = kernels::crop_box_mask(points, roi_, mask_);  // NaN points never pass
    const kernels::PointsSpan kept_span{std::span(kx_).first(kept), std::span(ky_).first(kept),
                                        std::span(kz_).first(kept)};
    kernels::compact_masked(points, mask_, kept_span, {});
    s.kept = static_cast<std::uint32_t>(kept);
    if (leaf_ == 0.0F) {
      std::ranges::copy(kept_span.x, block.voxels().x.begin());
      std::ranges::copy(kept_span.y, block.voxels().y.begin());
      std::ranges::copy(kept_span.z, block.voxels().z.begin());
      s.voxels = s.kept;
    } else if (auto voxels = kernels::voxel_grid(kept_span, leaf_, voxel_scratch_, block.voxels())) {
      s.voxels = static_cast<std::uint32_t>(*voxels);
    } else {
      s.voxels = 0;
      s.error.assign("preprocess: voxel grid failed");
    }
    out.emit(0, in);
  }

 private:
  kernels::AxisBox roi_;
  float leaf_;
  std::vector<std::uint8_t> mask_;
  std::vector<float> kx_, ky_, kz_;
  kernels::VoxelGridScratch voxel_scratch_;
};

class Table final : public FrameStage {
 public:
  Table(std::size_t capacity, kernels::RansacParams params)
      : FrameStage(capacity), params_(params), inliers_(capacity), pu_(capacity), pv_(capacity),
        hull_scratch_(capacity), hull_idx_(capacity + 1) {}

  void process(const Message& in, Emitter& out) noexcept override {
    const FrameBlock block = block_of(in, capacity_);
    FrameState& s = block.state();
    s.table_found = false;
    const kernels::PointsSpan all = block.voxels();
    const kernels::PointsView points{all.x.first(s.voxels), all.y.first(s.voxels), all.z.first(s.voxels)};
    auto plane = kernels::ransac_plane(points, params_, inliers_);
    if (!plane) {
      if (s.error.empty()) s.error.assign("table: no plane (too few points or degenerate)");
      out.emit(0, in);
      return;
    }
    const auto idx = std::span<const std::uint32_t>(inliers_).first(plane->inliers);
    kernels::project_to_plane(points, idx, kernels::make_plane_basis(plane->plane), pu_, pv_);
    const std::size_t h = kernels::convex_hull_2d(std::span<const double>(pu_).first(idx.size()),
                                                  std::span<const double>(pv_).first(idx.size()), hull_scratch_,
                                                  hull_idx_);
    if (h < 3 || h > MAX_HULL) {
      s.error.assign(h < 3 ? "table: the plane inliers have a degenerate hull" : "table: hull exceeds MAX_HULL");
      out.emit(0, in);
      return;
    }
    for (std::size_t k = 0; k < h; ++k) {
      block.hull_u()[k] = pu_[hull_idx_[k]];
      block.hull_v()[k] = pv_[hull_idx_[k]];
    }
    s.plane = plane->plane;
    s.plane_inliers = static_cast<std::uint32_t>(plane->inliers);
    s.hull_count = static_cast<std::uint32_t>(h);
    s.table_found = true;
    out.emit(0, in);
  }

 private:
  kernels::RansacParams params_;
  std::vector<std::uint32_t> inliers_;
  std::vector<double> pu_, pv_;
  std::vector<std::uint32_t> hull_scratch_, hull_idx_;
};

}  // namespace

// The objects kind is long enough for its own file (objects_node.cpp).
NodeResult make_objects_node(const ParamMap& params, const engine::NodeContext& context);

namespace {

NodeResult make_preprocess(const ParamMap& params, const engine::NodeContext& context) {
  auto capacity = frame_capacity(context);
  if (!capacity) return err(capacity.error());
  if (auto ok = params.only({"roi_min_x", "roi_min_y", "roi_min_z", "roi_max_x", "roi_max_y", "roi_max_z", "leaf"});
      !ok) {
    return err(ok.error());
  }
  kernels::AxisBox roi{{-1.0F, -1.0F, 0.3F}, {1.0F, 1.0F, 2.0F}};  // thesis: a ~2 m cube holding the table
  float leaf = 0.005F;
  std::string e;
  const char* keys[2][3] = {{"roi_min_x", "roi_min_y", "roi_min_z"}, {"roi_max_x", "roi_max_y", "roi_max_z"}};
  for (int axis = 0; axis < 3; ++axis) {
    take(params.number(keys[0][axis], roi.min[static_cast<std::size_t>(axis)], -100.0, 100.0),
         roi.min[static_cast<std::size_t>(axis)], e);
    take(params.number(keys[1][axis], roi.max[static_cast<std::size_t>(axis)], -100.0, 100.0),
         roi.max[static_cast<std::size_t>(axis)], e);
  }
  take(params.number("leaf", leaf, 0.0, 1.0), leaf, e);
  if (!e.empty()) return err(e);
  return std::unique_ptr<engine::Node>(new Preprocess(*capacity, roi, leaf));
}

NodeResult make_table(const ParamMap& params, const engine::NodeContext& context) {
  auto capacity = frame_capacity(context);
  if (!capacity) return err(capacity.error());
  if (auto ok = params.only({"tau", "iterations", "confidence", "seed"}); !ok) return err(ok.error());
  kernels::RansacParams ransac;  // thesis: tau = 0.02 m, 200 iterations
  std::string e;
  take(params.number("tau", ransac.tau, 1e-4, 1.0), ransac.tau, e);
  take(params.integer("iterations", ransac.max_iterations, 1, 100000), ransac.max_iterations, e);
  take(params.number("confidence", ransac.confidence, 0.0, 0.999999), ransac.confidence, e);
  take(params.integer("seed", 0x0f5eed5eed, 0, INT64_MAX), ransac.seed, e);
  if (!e.empty()) return err(e);
  return std::unique_ptr<engine::Node>(new Table(*capacity, ransac));
}

}  // namespace

void add_segment_nodes(engine::NodeRegistry& registry) {
  registry.add("preprocess", "drops NaN and out-of-ROI points, voxel grid: roi_min_x..roi_max_z (m), leaf (m, 0 = off)",
               make_preprocess);
  registry.add("table", "RANSAC table plane + support polygon: tau (m), iterations, confidence, seed", make_table);
  registry.add("objects",
               "prism + Euclidean clusters + C_size/C_edge: h_min, h_max, tolerance, min_points, max_points, "
               "min_size, max_size, edge_margin (m)",
               make_objects_node);
}

}  // namespace orthoflow::graphs
