// The path predicates and stage 1 of the tabletop chain (kernels/tabletop_stages.hpp):
// PlaneInputStage, the ROI with a strided pixel sample (organized frames) or a voxel grid. Stage 2
// is in table_stage.cpp, stage 3 in object_stage.cpp.
#include "kernels/tabletop_stages.hpp"

#include "kernels/cloud_stats.hpp"
#include "kernels/detail/stage_common.hpp"
#include "kernels/pixel_subsample.hpp"

namespace orthoflow::kernels {

namespace {

using detail::Clock;
using detail::fail;
using detail::ms_since;

PointsView first(PointsSpan s, std::size_t offset, std::size_t n) noexcept {
  return PointsView{s.x.subspan(offset, n), s.y.subspan(offset, n), s.z.subspan(offset, n)};
}

std::size_t cells(std::uint32_t extent, std::uint32_t stride) noexcept {
  return (extent + stride - 1) / stride;
}

constexpr std::size_t MIN_PLANE_POINTS = 3;  // RANSAC's minimum

/// FEW_POINTS_IN_ROI with the cloud's finite points: says whether the points are missing or
/// outside the ROI. Only on the failure path (a pass over the cloud).
SegmentationError few_points_in_roi(PointsView points, const AxisBox& roi,
                                    std::size_t inside) noexcept {
  SegmentationError e =
      fail(SegmentationError::Code::FEW_POINTS_IN_ROI, 0, static_cast<double>(inside));
  e.finite = cloud_stats(points).finite;
  e.roi = roi;
  return e;
}

}  // namespace

bool takes_organized_path(CloudView cloud, const SegmentationParams& params) noexcept {
  return params.use_organized && cloud.organized();
}

bool takes_strided_sample(CloudView cloud, const SegmentationParams& params) noexcept {
  const std::uint32_t s = params.organized_stride;
  return takes_organized_path(cloud, params) && s > 0 &&
         sample_lines(cloud.width, s) >= MIN_SAMPLE_LINES &&
         sample_lines(cloud.height, s) >= MIN_SAMPLE_LINES;
}

PlaneInputStage::PlaneInputStage(std::size_t max_points)
    : max_points_(max_points),
      mask_(max_points),
      kx_(max_points),
      ky_(max_points),
      kz_(max_points),
      voxel_scratch_(max_points) {}

Result<PlaneInput, SegmentationError> PlaneInputStage::run(CloudView cloud,
                                                           const SegmentationParams& p,
                                                           PointsSpan out) noexcept {
  using C = SegmentationError::Code;
  auto start = Clock::now();
  const std::size_t n = cloud.points.size();
  if (n > max_points_) return err(fail(C::CLOUD_TOO_LARGE, 0, static_cast<double>(n)));
  if (takes_organized_path(cloud, p) && n != std::size_t{cloud.width} * cloud.height) {
    SegmentationError e = fail(C::NOT_WIDTH_X_HEIGHT, 0, static_cast<double>(n));
    e.width = cloud.width;
    e.height = cloud.height;
    return err(e);
  }
  if (!takes_strided_sample(cloud, p)) return every_kept_point(cloud, p, out);
  // The plane and hull need a sample about as dense as 5 mm voxels, not a voxel grid over every
  // kept pixel: a strided pixel sample costs 1/stride^2 of the frame and needs no sort. RANSAC
  // scores its hypotheses on the sample at twice the stride (a quarter of the points), written
  // after the dense one.
  const std::uint32_t s = p.organized_stride;
  const std::size_t dense_max = cells(cloud.width, s) * cells(cloud.height, s);
  const std::size_t sparse_max = cells(cloud.width, 2 * s) * cells(cloud.height, 2 * s);
  if (out.size() < dense_max) {
    return err(fail(C::OUTPUT_TOO_SMALL, 0, static_cast<double>(dense_max)));
  }
  const std::size_t dense = pixel_subsample(cloud, s, p.roi, out);
  // Too few sampled pixels for a plane (a frame with little inside the ROI): every kept pixel may
  // still hold enough, as for an unorganized cloud.
  if (dense < MIN_PLANE_POINTS && out.size() >= n) return every_kept_point(cloud, p, out);
  // No room for the scoring sample after the dense one (stride 1 on a full frame): RANSAC then
  // scores on the dense sample itself, as for small frames.
  const PointsSpan rest{out.x.subspan(dense), out.y.subspan(dense), out.z.subspan(dense)};
  const std::size_t sparse =
      out.size() >= dense_max + sparse_max ? pixel_subsample(cloud, 2 * s, p.roi, rest) : 0;
  return PlaneInput{first(out, 0, dense), first(out, dense, sparse), dense, ms_since(start), 0.0};
}

/// The unorganized path (and the organized one without a strided sample): ROI crop, then the voxel
/// grid, or every kept point when leaf == 0.
Result<PlaneInput, SegmentationError> PlaneInputStage::every_kept_point(CloudView cloud,
                                                                        const SegmentationParams& p,
                                                                        PointsSpan out) noexcept {
  using C = SegmentationError::Code;
  auto start = Clock::now();
  const std::size_t n = cloud.points.size();
  if (out.size() < n) return err(fail(C::OUTPUT_TOO_SMALL, 0, static_cast<double>(n)));
  const std::size_t kept = crop_box_mask(cloud.points, p.roi, mask_);  // NaN points never pass
  if (kept < MIN_PLANE_POINTS) return err(few_points_in_roi(cloud.points, p.roi, kept));
  if (p.leaf == 0.0F) {
    compact_masked(cloud.points, mask_,
                   PointsSpan{out.x.first(kept), out.y.first(kept), out.z.first(kept)}, {});
    return PlaneInput{first(out, 0, kept), {}, kept, ms_since(start), 0.0};
  }
  const PointsSpan kept_span{std::span(kx_).first(kept), std::span(ky_).first(kept),
                             std::span(kz_).first(kept)};
  compact_masked(cloud.points, mask_, kept_span, {});
  const double filter_ms = ms_since(start);
  auto voxel_result = voxel_grid(kept_span, p.leaf, voxel_scratch_, out);
  if (!voxel_result) {
    const auto& e = voxel_result.error();
    return err(fail(C::VOXEL_GRID_FAILED, static_cast<std::uint8_t>(e.code), e.value));
  }
  return PlaneInput{first(out, 0, *voxel_result), {}, kept, filter_ms, ms_since(start)};
}

}  // namespace orthoflow::kernels
