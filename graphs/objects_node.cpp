// The `objects` kind: prism over the table polygon, Euclidean clusters, per-cluster statistics and
// the candidate constraints of thesis Table 3.1 that need no tracking (C_size, C_edge). Kept objects
// are gathered (a counting sort by cluster) into the block's object-point region so that describe
// reads each object as one contiguous span.
#include <algorithm>
#include <array>
#include <cmath>
#include <vector>

#include "graphs/node_support.hpp"
#include "kernels/convex_hull.hpp"
#include "kernels/euclidean_cluster.hpp"
#include "kernels/polygonal_prism.hpp"

namespace orthoflow::graphs {

namespace {

using engine::Emitter;
using engine::Message;

const engine::PortSpec PORTS[] = {FRAME_IN, FRAME_OUT};
constexpr std::size_t TRUTH_BINS = 256;
constexpr std::size_t MAX_MERGE = 256;   // clusters beyond this are not merged (a cluttered frame)  // ground-truth label values counted per object (synthetic: 100 + id)

struct ObjectParams {
  float h_min = 0.005F, h_max = 0.5F;
  kernels::ClusterParams cluster{0.02F, 50, 200000, 2};
  float min_size = 0.02F;     // C_size: the largest extent must reach this (m)
  float max_size = 0.5F;      // C_size: every extent at most this (graspable)
  float edge_margin = 0.02F;  // C_edge: centroid at least this far inside the table polygon (m)
  float merge_overlap = 0.3F; // merge clusters whose footprints overlap by this share of the smaller (0 = off)
};

// Distance from (u, v) to the nearest edge of a convex polygon (positive inside).
double inside_distance(double u, double v, std::span<const double> hu, std::span<const double> hv, std::size_t n) {
  double best = 1e300;
  for (std::size_t k = 0; k < n; ++k) {
    const std::size_t j = (k + 1) % n;
    const double ex = hu[j] - hu[k], ey = hv[j] - hv[k];
    const double len = std::hypot(ex, ey);
    if (len == 0.0) continue;
    best = std::min(best, (ex * (v - hv[k]) - ey * (u - hu[k])) / len);  // counter-clockwise: left is inside
  }
  return best;
}

class Objects final : public engine::Node {
 public:
  Objects(std::size_t capacity, const ObjectParams& p)
      : capacity_(capacity), p_(p), heights_(capacity), mask_(capacity), labels_(capacity),
        moments_(capacity / std::max<std::size_t>(1, p.cluster.min_size) + 1), stats_(moments_.size()),
        slot_of_(moments_.size()), truth_counts_(MAX_OBJECTS * TRUTH_BINS), scratch_(capacity) {}
  std::span<const engine::PortSpec> inputs() const noexcept override { return {PORTS, 1}; }
  std::span<const engine::PortSpec> outputs() const noexcept override { return {PORTS + 1, 1}; }
  bool stateful() const noexcept override { return true; }

  void process(const Message& in, Emitter& out) noexcept override {
    const FrameBlock block = block_of(in, capacity_);
    FrameState& s = block.state();
    s.object_count = s.clusters = s.rejected_size = s.rejected_edge = 0;
    auto frame = block.frame();
    if (s.table_found && frame) segment(block, *frame);
    out.emit(0, in);
  }

 private:
  void segment(const FrameBlock& block, const engine::FrameView& frame) noexcept {
    FrameState& s = block.state();
    const bool organized = frame.cloud.organized();
    const kernels::PointsSpan v = block.voxels();
    const kernels::PointsView target =
        organized ? frame.cloud.points
                  : kernels::PointsView{v.x.first(s.voxels), v.y.first(s.voxels), v.z.first(s.voxels)};
    const auto hu = std::span<const double>(block.hull_u()).first(s.hull_count);
    const auto hv = std::span<const double>(block.hull_v()).first(s.hull_count);
    const kernels::PlaneBasis basis = kernels::make_plane_basis(s.plane);
    const kernels::Prism prism{s.plane, basis, hu, hv, p_.h_min, p_.h_max};
    kernels::polygonal_prism(target, prism, heights_, mask_);
    const auto mask = std::span<const std::uint8_t>(mask_).first(target.size());
    auto labels = std::span(labels_).first(target.size());
    auto found = organized ? kernels::euclidean_cluster_organized({target, frame.cloud.width, frame.cloud.height},
                                                                  mask, p_.cluster, scratch_, labels)
                           : kernels::euclidean_cluster(target, mask, p_.cluster, scratch_, labels);
    if (!found) {
      s.error.assign("objects: clustering failed");
      return;
    }
    std::size_t clusters = std::min(*found, stats_.size());
    if (p_.merge_overlap > 0.0F) clusters = merge_stacked(target, labels, basis, clusters);
    kernels::cluster_stats(target, labels, moments_, std::span(stats_).first(clusters));
    s.clusters = static_cast<std::uint32_t>(clusters);
    select(block, basis, hu, hv, clusters);
    gather(block, target, labels, organized ? frame.label : std::span<const std::uint32_t>{});
  }

  // Clusters whose footprints on the table overlap are one object seen in pieces (a bowl's near and far
  // walls, a mug's rim and body when a depth edge cuts them apart): objects on a table do not overlap
  // from above. Union-find over the pairs, ids renumbered by lowest member (deterministic).
  std::size_t merge_stacked(kernels::PointsView target, std::span<std::int32_t> labels, const kernels::PlaneBasis& b,
                            std::size_t clusters) noexcept {
    if (clusters < 2 || clusters > MAX_MERGE) return clusters;
    for (std::size_t c = 0; c < clusters; ++c) foot_[c] = {1e30, -1e30, 1e30, -1e30};
    for (std::size_t i = 0; i < target.size(); ++i) {
      if (labels[i] < 0) continue;
      const double x = target.x[i] - b.origin[0], y = target.y[i] - b.origin[1], z = target.z[i] - b.origin[2];
      const double u = x * b.u[0] + y * b.u[1] + z * b.u[2], v = x * b.v[0] + y * b.v[1] + z * b.v[2];
      auto& f = foot_[static_cast<std::size_t>(labels[i])];
      f = {std::min(f[0], u), std::max(f[1], u), std::min(f[2], v), std::max(f[3], v)};
    }
    for (std::size_t c = 0; c < clusters; ++c) root_[c] = static_cast<std::int32_t>(c);
    for (std::size_t i = 0; i < clusters; ++i) {
      for (std::size_t j = i + 1; j < clusters; ++j) {
        const auto &a = foot_[i], &c = foot_[j];
        const double w = std::min(a[1], c[1]) - std::max(a[0], c[0]), h = std::min(a[3], c[3]) - std::max(a[2], c[2]);
        const double smaller = std::min((a[1] - a[0]) * (a[3] - a[2]), (c[1] - c[0]) * (c[3] - c[2]));
        if (w > 0.0 && h > 0.0 && w * h >= p_.merge_overlap * smaller) unite(i, j);
      }
    }
    std::size_t merged = 0;
    for (std::size_t c = 0; c < clusters; ++c) {
      const auto r = static_cast<std::size_t>(find(c));
      new_id_[c] = r == c ? static_cast<std::int32_t>(merged++) : new_id_[r];  // a root is its lowest member
    }
    if (merged == clusters) return clusters;
    for (std::size_t i = 0; i < target.size(); ++i) {
      if (labels[i] >= 0) labels[i] = new_id_[static_cast<std::size_t>(labels[i])];
    }
    return merged;
  }

  std::int32_t find(std::size_t c) noexcept {
    while (root_[c] != static_cast<std::int32_t>(c)) c = static_cast<std::size_t>(root_[c] = root_[static_cast<std::size_t>(root_[c])]);
    return static_cast<std::int32_t>(c);
  }
  void unite(std::size_t a, std::size_t b) noexcept {
    const std::int32_t ra = find(a), rb = find(b);
    root_[static_cast<std::size_t>(std::max(ra, rb))] = std::min(ra, rb);  // the lowest id stays the root
  }

  // C_size and C_edge; survivors get consecutive object slots (cluster order: deterministic).
  void select(const FrameBlock& block, const kernels::PlaneBasis& basis, std::span<const double> hu,
              std::span<const double> hv, std::size_t clusters) noexcept {
    FrameState& s = block.state();
    for (std::size_t c = 0; c < clusters; ++c) {
      slot_of_[c] = -1;
      const kernels::ClusterStats& st = stats_[c];
      float largest = 0.0F, smallest = 1e30F;
      for (std::size_t a = 0; a < 3; ++a) {
        largest = std::max(largest, st.obb_max[a] - st.obb_min[a]);
        smallest = std::min(smallest, st.obb_max[a] - st.obb_min[a]);
      }
      if (st.points == 0 || largest < p_.min_size || largest > p_.max_size) {
        ++s.rejected_size;
        continue;
      }
      double u = 0.0, w = 0.0;
      const std::array<std::uint32_t, 1> zero{0};
      const kernels::PointsView centroid{{&st.centroid[0], 1}, {&st.centroid[1], 1}, {&st.centroid[2], 1}};
      kernels::project_to_plane(centroid, zero, basis, {&u, 1}, {&w, 1});
      if (inside_distance(u, w, hu, hv, hu.size()) < p_.edge_margin) {
        ++s.rejected_edge;
        continue;
      }
      if (s.object_count == MAX_OBJECTS) break;
      slot_of_[c] = static_cast<std::int32_t>(s.object_count);
      ObjectRecord& o = s.objects[s.object_count++];
      o = ObjectRecord{};
      o.count = static_cast<std::uint32_t>(st.points);
      o.stats = st;
    }
  }

  // Counting sort of the kept objects' points into the object-point region, plus the majority
  // ground-truth label of each object when the frame carries labels.
  void gather(const FrameBlock& block, kernels::PointsView target, std::span<const std::int32_t> labels,
              std::span<const std::uint32_t> truth) noexcept {
    FrameState& s = block.state();
    std::uint32_t next = 0;
    for (std::uint32_t k = 0; k < s.object_count; ++k) {
      s.objects[k].first = next;
      next += s.objects[k].count;
      s.objects[k].count = 0;
    }
    std::fill(truth_counts_.begin(), truth_counts_.begin() + s.object_count * TRUTH_BINS, 0U);
    const kernels::PointsSpan dst = block.object_points();
    for (std::size_t i = 0; i < target.size(); ++i) {
      if (labels[i] < 0 || static_cast<std::size_t>(labels[i]) >= s.clusters) continue;
      const std::int32_t k = slot_of_[static_cast<std::size_t>(labels[i])];
      if (k < 0) continue;
      ObjectRecord& o = s.objects[static_cast<std::size_t>(k)];
      const std::size_t at = o.first + o.count++;
      dst.x[at] = target.x[i];
      dst.y[at] = target.y[i];
      dst.z[at] = target.z[i];
      if (!truth.empty() && truth[i] < TRUTH_BINS) ++truth_counts_[static_cast<std::size_t>(k) * TRUTH_BINS + truth[i]];
    }
    if (truth.empty()) return;
    for (std::uint32_t k = 0; k < s.object_count; ++k) label_truth(s, k);
  }

  void label_truth(FrameState& s, std::uint32_t k) const noexcept {
    const auto counts = std::span(truth_counts_).subspan(k * TRUTH_BINS, TRUTH_BINS);
    const auto best = static_cast<std::uint32_t>(std::max_element(counts.begin() + 1, counts.end()) - counts.begin());
    ObjectRecord& o = s.objects[k];
    if (counts[best] * 2 < o.count) return;  // no majority: leave unlabelled
    o.truth_label = best;
    for (std::uint32_t t = 0; t < s.truth_count; ++t) {
      if (s.truth[t].label == best) o.truth_category = s.truth[t].category;
    }
  }

  std::size_t capacity_;
  ObjectParams p_;
  std::vector<float> heights_;
  std::vector<std::uint8_t> mask_;
  std::vector<std::int32_t> labels_;
  std::vector<kernels::ClusterMoments> moments_;
  std::vector<kernels::ClusterStats> stats_;
  std::vector<std::int32_t> slot_of_;
  std::vector<std::uint32_t> truth_counts_;
  std::array<std::array<double, 4>, MAX_MERGE> foot_{};  // u_min, u_max, v_min, v_max
  std::array<std::int32_t, MAX_MERGE> root_{}, new_id_{};
  kernels::ClusterScratch scratch_;
};

}  // namespace

NodeResult make_objects_node(const engine::ParamMap& params, const engine::NodeContext& context) {
  auto capacity = frame_capacity(context);
  if (!capacity) return err(capacity.error());
  if (auto ok = params.only({"h_min", "h_max", "tolerance", "min_points", "max_points", "pixel_radius", "min_size",
                             "max_size", "edge_margin", "merge_overlap"});
      !ok) {
    return err(ok.error());
  }
  ObjectParams p;
  std::string e;
  take(params.number("h_min", p.h_min, -1.0, 10.0), p.h_min, e);
  take(params.number("h_max", p.h_max, -1.0, 10.0), p.h_max, e);
  take(params.number("tolerance", p.cluster.tolerance, 1e-4, 1.0), p.cluster.tolerance, e);
  take(params.integer("min_points", p.cluster.min_size, 1, UINT32_MAX), p.cluster.min_size, e);
  take(params.integer("max_points", p.cluster.max_size, 1, UINT32_MAX), p.cluster.max_size, e);
  take(params.integer("pixel_radius", p.cluster.pixel_radius, 1, 16), p.cluster.pixel_radius, e);
  take(params.number("min_size", p.min_size, 0.0, 10.0), p.min_size, e);
  take(params.number("max_size", p.max_size, 0.0, 10.0), p.max_size, e);
  take(params.number("edge_margin", p.edge_margin, -1.0, 1.0), p.edge_margin, e);
  take(params.number("merge_overlap", p.merge_overlap, 0.0, 1.0), p.merge_overlap, e);
  if (!e.empty()) return err(e);
  if (p.h_min >= p.h_max) return err(std::string("objects: h_min must be below h_max"));
  return std::unique_ptr<engine::Node>(new Objects(*capacity, p));
}

}  // namespace orthoflow::graphs
