// The table verdict (kernels/table_verdict.hpp).
#include "kernels/table_verdict.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace orthoflow::kernels {

std::string_view table_reason_name(TableReason reason) noexcept {
  switch (reason) {
    case TableReason::ACCEPTED:
      return "accepted";
    case TableReason::HELD:
      return "held";
    case TableReason::NO_PLANE:
      return "no_plane";
    case TableReason::NOT_LEVEL:
      return "not_level";
    case TableReason::OUT_OF_RANGE:
      return "out_of_range";
    case TableReason::TOO_SMALL:
      return "too_small";
  }
  return "unknown";
}

double polygon_area(std::span<const double> u, std::span<const double> v) noexcept {
  const std::size_t n = std::min(u.size(), v.size());
  if (n < 3) return 0.0;
  double twice = 0.0;
  for (std::size_t i = 0, j = n - 1; i < n; j = i++) twice += u[j] * v[i] - u[i] * v[j];
  return 0.5 * std::fabs(twice);
}

TableJudgement judge_table(const Plane& plane, std::size_t inliers, std::size_t sample,
                           std::span<const double> hull_u, std::span<const double> hull_v,
                           const std::array<float, 3>* up,
                           const TableVerdictParams& params) noexcept {
  TableJudgement j;
  const auto& n = plane.normal;
  j.height_m = std::fabs(plane.d);
  j.share = sample == 0 ? 0.0F : static_cast<float>(double(inliers) / double(sample));
  j.area_m2 = static_cast<float>(polygon_area(hull_u, hull_v));
  j.tilt_deg = std::numeric_limits<float>::quiet_NaN();
  if (up != nullptr) {
    // The normal faces the sensor; a table below the camera then points up. NaN fails the test.
    const float cos = n[0] * (*up)[0] + n[1] * (*up)[1] + n[2] * (*up)[2];
    j.tilt_deg = std::acos(std::clamp(cos, -1.0F, 1.0F)) * 57.29577951F;
    if (!(j.tilt_deg <= params.max_tilt_deg)) {
      j.reason = TableReason::NOT_LEVEL;
      return j;
    }
  }
  if (!(j.height_m >= params.min_height_m && j.height_m <= params.max_height_m)) {
    j.reason = TableReason::OUT_OF_RANGE;
    return j;
  }
  if (!(j.share >= params.min_share && j.area_m2 >= params.min_area_m2)) {
    j.reason = TableReason::TOO_SMALL;
    return j;
  }
  j.reason = TableReason::ACCEPTED;
  return j;
}

}  // namespace orthoflow::kernels
