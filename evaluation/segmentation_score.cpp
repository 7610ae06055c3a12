#include "evaluation/segmentation_score.hpp"

#include <algorithm>
#include <cmath>
#include <map>
#include <tuple>
#include <vector>

#include "kernels/ransac_plane.hpp"

namespace orthoflow::evaluation {

SegmentationCounts& SegmentationCounts::operator+=(const SegmentationCounts& o) noexcept {
  truth += o.truth;
  predicted += o.predicted;
  matched += o.matched;
  over += o.over;
  under += o.under;
  matched_iou += o.matched_iou;
  return *this;
}

SegmentationCounts score_objects(std::span<const std::uint32_t> truth,
                                 std::span<const std::uint32_t> predicted) {
  std::map<std::uint32_t, std::size_t> truth_size, predicted_size;
  std::map<std::pair<std::uint32_t, std::uint32_t>, std::size_t> both;
  for (std::size_t i = 0; i < truth.size(); ++i) {
    const std::uint32_t t = truth_object(truth[i]);
    const std::uint32_t p = predicted[i] >= 2 ? predicted[i] : 0;
    if (t != 0) ++truth_size[t];
    if (p != 0) ++predicted_size[p];
    if (t != 0 && p != 0) ++both[{t, p}];
  }
  SegmentationCounts c;
  c.truth = truth_size.size();
  c.predicted = predicted_size.size();
  std::vector<std::tuple<double, std::uint32_t, std::uint32_t>> pairs;  // IoU, truth, prediction
  std::map<std::uint32_t, int> parts_of_truth, objects_in_prediction;
  for (const auto& [key, n] : both) {
    const auto [t, p] = key;
    const double iou = double(n) / double(truth_size[t] + predicted_size[p] - n);
    if (iou >= 0.5) pairs.emplace_back(iou, t, p);
    if (double(n) >= 0.1 * double(truth_size[t])) {
      ++parts_of_truth[t];
      ++objects_in_prediction[p];
    }
  }
  // Highest IoU first; ties by label so that the result never depends on the map's layout.
  std::sort(pairs.begin(), pairs.end(), [](const auto& a, const auto& b) {
    return std::get<0>(a) != std::get<0>(b) ? std::get<0>(a) > std::get<0>(b) : a < b;
  });
  std::map<std::uint32_t, bool> truth_taken, predicted_taken;
  for (const auto& [iou, t, p] : pairs) {
    if (truth_taken[t] || predicted_taken[p]) continue;
    truth_taken[t] = predicted_taken[p] = true;
    ++c.matched;
    c.matched_iou += iou;
  }
  for (const auto& [t, parts] : parts_of_truth) c.over += parts >= 2 ? 1U : 0U;
  for (const auto& [p, objects] : objects_in_prediction) c.under += objects >= 2 ? 1U : 0U;
  return c;
}

PlaneQuality score_plane(kernels::PointsView points, std::span<const std::uint32_t> truth,
                         const kernels::Plane& plane) {
  PlaneQuality q;
  std::vector<std::uint32_t> table;
  double sum_sq = 0.0;
  const auto& n = plane.normal;
  for (std::size_t i = 0; i < truth.size(); ++i) {
    const double x = points.x[i], y = points.y[i], z = points.z[i];
    if (!truth_table(truth[i]) || !std::isfinite(x) || !std::isfinite(y) || !std::isfinite(z)) {
      continue;
    }
    table.push_back(static_cast<std::uint32_t>(i));
    const double dist = n[0] * x + n[1] * y + n[2] * z + plane.d;
    q.near += std::fabs(dist) <= PlaneQuality::NEAR_M ? 1U : 0U;
    sum_sq += dist * dist;
  }
  q.table_points = table.size();
  if (table.size() < 3) return q;
  q.rms_m = std::sqrt(sum_sq / double(table.size()));
  const kernels::Plane fit = kernels::fit_plane(points, table);
  const double cos = std::fabs(double(n[0]) * fit.normal[0] + double(n[1]) * fit.normal[1] +
                               double(n[2]) * fit.normal[2]);
  q.angle_deg = std::acos(std::min(1.0, cos)) * 180.0 / 3.14159265358979323846;
  return q;
}

}  // namespace orthoflow::evaluation
