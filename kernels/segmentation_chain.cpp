#include "kernels/segmentation_chain.hpp"

#include <algorithm>
#include <chrono>

namespace orthoflow::kernels {

namespace {
using Clock = std::chrono::steady_clock;
double ms_between(Clock::time_point a, Clock::time_point b) {
  return std::chrono::duration<double, std::milli>(b - a).count();
}
}  // namespace

SegmentationChain::SegmentationChain(std::size_t max_points, const SegmentationParams& params,
                                     const CandidateParams& candidates)
    : params_(params),
      candidate_params_(candidates),
      px_(max_points),
      py_(max_points),
      pz_(max_points),
      hull_u_(max_points + 1),
      hull_v_(max_points + 1),
      plane_input_(max_points),
      table_(max_points),
      objects_(max_points, params.cluster.min_size),
      slot_of_(max_points / std::max<std::size_t>(1, params.cluster.min_size) + 1),
      candidates_(slot_of_.size()) {}

Result<SegmentationResult, SegmentationError> SegmentationChain::run(CloudView cloud) {
  const auto start = Clock::now();
  SegmentationTimings t;
  auto input_result = plane_input_.run(cloud, params_, PointsSpan{px_, py_, pz_});
  if (!input_result) return err(input_result.error());
  t.filter = input_result->filter_ms;
  t.voxel = input_result->voxel_ms;
  const auto plane_start = Clock::now();
  auto table_result = table_.run(*input_result, params_, hull_u_, hull_v_);
  if (!table_result) return err(table_result.error());
  t.plane = ms_between(plane_start, Clock::now());
  auto objects_result = objects_.run(cloud, *input_result, *table_result, params_);
  if (!objects_result) return err(objects_result.error());
  t.prism = objects_result->prism_ms;
  t.cluster = objects_result->cluster_ms;
  const auto candidates_start = Clock::now();
  const auto clusters = objects_result->clusters;
  const CandidateCounts counts =
      select_candidates(clusters, table_result->plane.plane, table_result->hull_u,
                        table_result->hull_v, candidate_params_, candidates_.size(), slot_of_);
  for (std::size_t c = 0; c < clusters.size(); ++c) {
    if (slot_of_[c] >= 0) candidates_[static_cast<std::size_t>(slot_of_[c])] = clusters[c];
  }
  const auto end = Clock::now();
  t.candidates = ms_between(candidates_start, end);
  t.total = ms_between(start, end);
  return SegmentationResult{table_result->plane,
                            table_result->check,
                            clusters,
                            std::span<const ClusterStats>(candidates_).first(counts.kept),
                            counts,
                            objects_result->labels,
                            std::span<const std::int32_t>(slot_of_).first(clusters.size()),
                            takes_organized_path(cloud, params_),
                            t,
                            table_result->hull_u,
                            table_result->hull_v,
                            input_result->dense.size(),
                            objects_result->stride,
                            objects_result->refined};
}

}  // namespace orthoflow::kernels
