#pragma once
/// @file
/// @brief Scores one segmented frame against mOSD-style per-pixel ground truth
/// (docs/SEGMENTATION.md, "Evaluation"). Ground truth: 0 invalid, 1-9 table, 10k + j part j of
/// object k (k >= 2; the parts of one object are one object). Prediction: the frame_labels()
/// convention (0 none, 1 table, k >= 2 object). An object is found when one predicted object covers
/// it at pixel IoU >= 0.5 (pairs taken by decreasing IoU, each object and prediction at most once).
/// Over-segmented object: >= 2 predictions each hold >= 10 % of its pixels; under-segmenting
/// prediction: >= 2 objects each put >= 10 % of their pixels in it. Plane quality: the labelled
/// table points within 1 cm of the plane, their RMS distance, and the angle to the least-squares
/// plane of those points.
#include <cstddef>
#include <cstdint>
#include <span>

#include "kernels/plane_distance.hpp"
#include "kernels/point_cloud.hpp"

namespace orthoflow::evaluation {

/// @brief Object-level counts of one frame or a sum of frames.
struct SegmentationCounts {
  std::size_t truth = 0;      ///< ground-truth objects
  std::size_t predicted = 0;  ///< predicted objects
  std::size_t matched = 0;    ///< one-to-one matches at IoU >= 0.5
  std::size_t over = 0;       ///< over-segmented ground-truth objects
  std::size_t under = 0;      ///< predictions that hold two or more objects
  double matched_iou = 0.0;   ///< sum of the matches' IoU
  [[nodiscard]] double precision() const noexcept {
    return predicted == 0 ? (truth == 0 ? 1.0 : 0.0) : double(matched) / double(predicted);
  }
  [[nodiscard]] double recall() const noexcept {
    return truth == 0 ? 1.0 : double(matched) / double(truth);
  }
  SegmentationCounts& operator+=(const SegmentationCounts& o) noexcept;
};

/// @brief The plane against the labelled table points.
struct PlaneQuality {
  static constexpr double NEAR_M = 0.01;   ///< "within 1 cm"
  static constexpr double CORRECT = 0.90;  ///< share of table points near the plane for "correct"
  std::size_t table_points = 0;            ///< finite ground-truth table points
  std::size_t near = 0;                    ///< of those, within NEAR_M of the plane
  double rms_m = 0.0;                      ///< RMS distance of the table points to the plane
  double angle_deg = 0.0;  ///< between the plane's normal and the table points' least-squares one
  [[nodiscard]] double share() const noexcept {
    return table_points == 0 ? 0.0 : double(near) / double(table_points);
  }
  [[nodiscard]] bool correct() const noexcept { return table_points > 0 && share() >= CORRECT; }
};

struct FrameScore {
  SegmentationCounts objects;
  PlaneQuality plane;
};

/// @brief Ground-truth object of an mOSD label (label / 10 for labels >= 20), or 0.
[[nodiscard]] constexpr std::uint32_t truth_object(std::uint32_t label) noexcept {
  return label >= 20 ? label / 10 : 0;
}
/// @brief True for an mOSD table label (1-9).
[[nodiscard]] constexpr bool truth_table(std::uint32_t label) noexcept {
  return label >= 1 && label <= 9;
}

/// @brief Object counts of @p predicted against @p truth. @pre equal sizes.
[[nodiscard]] SegmentationCounts score_objects(std::span<const std::uint32_t> truth,
                                               std::span<const std::uint32_t> predicted);
/// @brief Plane quality of @p plane against the table points of @p truth in @p points.
[[nodiscard]] PlaneQuality score_plane(kernels::PointsView points,
                                       std::span<const std::uint32_t> truth,
                                       const kernels::Plane& plane);

}  // namespace orthoflow::evaluation
