// The `objects` kind: kernels::ObjectStage (prism over the table polygon, Euclidean clusters,
// footprint merge, per-cluster statistics) and the candidate constraints of thesis Table 3.1 that
// need no tracking (kernels::select_candidates: C_size, C_edge), then the gather of each kept
// object's points into the block's object-point region (one contiguous span per object, for
// describe) with the majority ground-truth label of its pixels when the frame carries labels. The
// same code as the chain.
#include <algorithm>
#include <array>
#include <vector>

#include "graphs/nodes/budget_counters.hpp"
#include "graphs/nodes/labels_writer.hpp"
#include "graphs/nodes/node_support.hpp"
#include "graphs/nodes/segment_nodes.hpp"
#include "graphs/nodes/segment_params.hpp"
#include "kernels/object_candidates.hpp"

namespace orthoflow::graphs {

namespace {

using engine::Emitter;
using engine::Message;

const engine::PortSpec PORTS[] = {FRAME_IN, FRAME_OUT};
constexpr std::size_t TRUTH_BINS =
    256;  // ground-truth label values counted per object (synthetic: 100 + id)

class Objects final : public engine::Node {
 public:
  Objects(std::size_t capacity, std::string name, const TabletopSegmentation& p,
          LabelsWriter* labels)
      : capacity_(capacity),
        labels_(labels),
        name_(std::move(name)),
        p_(p),
        stage_(capacity, p.stages.cluster.min_size),
        slot_of_(capacity / std::max<std::size_t>(1, p.stages.cluster.min_size) + 1),
        truth_counts_(MAX_OBJECTS * TRUTH_BINS) {}
  std::span<const engine::PortSpec> inputs() const noexcept override { return {PORTS, 1}; }
  std::span<const engine::PortSpec> outputs() const noexcept override { return {PORTS + 1, 1}; }
  bool stateful() const noexcept override { return true; }

  void process(const Message& in, Emitter& out) noexcept override {
    const FrameBlock block = block_of(in, capacity_);
    FrameState& s = block.state();
    s.object_count = s.clusters = s.rejected_size = s.rejected_edge = s.rejected_capacity = 0;
    s.prism_points = 0;
    s.stride = 1;
    s.refined = true;
    auto frame = block.frame();
    labelled_ = false;
    if (s.table_found && frame) segment(block, *frame);
    if (labels_ != nullptr && frame && !labelled_) {  // no table (or no objects stage): all 0
      labels_->offer(frame->header->frame_id, frame->cloud, s.plane, p_.stages.ransac.tau, s.roi,
                     {}, {});
    }
    budget_.record(s);
    out.emit(0, in);
  }
  const char* counter_group() const noexcept override { return "budget"; }
  std::size_t device_counters(std::span<engine::DeviceCounter> out) const noexcept override {
    return budget_.read(out);
  }

 private:
  void segment(const FrameBlock& block, const engine::FrameView& frame) noexcept {
    FrameState& s = block.state();
    // The stage must see the frame as preprocess saw it: the same ROI and the same path.
    kernels::SegmentationParams params = p_.stages;
    params.roi = s.roi;
    params.use_organized = s.organized_path;
    const kernels::TableModel table{{s.plane, s.plane_inliers, 0},
                                    std::span<const double>(block.hull_u()).first(s.hull_count),
                                    std::span<const double>(block.hull_v()).first(s.hull_count)};
    auto found = stage_.run(frame.cloud, plane_input(block), table, params);
    if (!found) {
      s.error.set(name_, found.error());
      return;
    }
    s.clusters = static_cast<std::uint32_t>(found->clusters.size());
    s.prism_points = static_cast<std::uint32_t>(found->prism_points);
    s.stride = static_cast<std::uint8_t>(found->stride);
    s.refined = found->refined;
    const kernels::CandidateCounts counts = kernels::select_candidates(
        found->clusters, s.plane, table.hull_u, table.hull_v, p_.candidates, MAX_OBJECTS, slot_of_);
    s.rejected_size = static_cast<std::uint32_t>(counts.rejected_size);
    s.rejected_edge = static_cast<std::uint32_t>(counts.rejected_edge);
    s.rejected_capacity = static_cast<std::uint32_t>(counts.over_capacity);
    s.object_count = static_cast<std::uint32_t>(counts.kept);
    for (std::size_t c = 0; c < found->clusters.size(); ++c) {
      if (slot_of_[c] < 0) continue;
      ObjectRecord& o = s.objects[static_cast<std::size_t>(slot_of_[c])];
      o = ObjectRecord{};
      o.stats = found->clusters[c];
      sizes_[static_cast<std::size_t>(slot_of_[c])] = found->clusters[c].points;
    }
    gather(block, *found, s.organized_path ? frame.label : std::span<const std::uint32_t>{});
    if (labels_ != nullptr && s.organized_path) {
      labels_->offer(frame.header->frame_id, frame.cloud, s.plane, p_.stages.ransac.tau, s.roi,
                     found->labels,
                     std::span<const std::int32_t>(slot_of_).first(found->clusters.size()));
      labelled_ = true;
    }
  }

  void gather(const FrameBlock& block, const kernels::ObjectClusters& found,
              std::span<const std::uint32_t> truth) {
    FrameState& s = block.state();
    const auto sizes = std::span<const std::size_t>(sizes_).first(s.object_count);
    kernels::gather_candidates(found.target, found.labels, found.members, slot_of_, sizes,
                               block.object_points(), spans_, truth, truth.empty() ? 0 : TRUTH_BINS,
                               truth_counts_);
    for (std::uint32_t k = 0; k < s.object_count; ++k) {
      ObjectRecord& o = s.objects[k];
      o.first = spans_[k].first;
      o.count = spans_[k].count;
      if (truth.empty()) continue;
      o.truth_label = kernels::majority_tag(
          std::span(truth_counts_).subspan(k * TRUTH_BINS, TRUTH_BINS), o.count);
      for (std::uint32_t t = 0; t < s.truth_count && o.truth_label != 0; ++t) {
        if (s.truth[t].label == o.truth_label) o.truth_category = s.truth[t].category;
      }
    }
  }

  std::size_t capacity_;
  LabelsWriter* labels_;   // --labels-out, or null
  bool labelled_ = false;  // this frame's labels were offered
  std::string name_;
  TabletopSegmentation p_;
  BudgetCounters budget_;
  kernels::ObjectStage stage_;
  std::vector<std::int32_t> slot_of_;
  std::vector<std::uint32_t> truth_counts_;
  std::array<std::size_t, MAX_OBJECTS> sizes_{};
  std::array<kernels::CandidateSpan, MAX_OBJECTS> spans_{};
};

}  // namespace

NodeResult make_objects_node(const engine::ParamMap& params, const engine::NodeContext& context,
                             LabelsWriter* labels) {
  auto capacity = frame_capacity(context);
  if (!capacity) return err(capacity.error());
  TabletopSegmentation p;
  if (auto ok = parse_objects_params(params, p); !ok) return err(ok.error());
  return std::unique_ptr<engine::Node>(
      new Objects(*capacity, std::string(context.name), p, labels));
}

}  // namespace orthoflow::graphs
