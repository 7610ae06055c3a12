#include "drivers/kinect/kinect_depth.hpp"

#include <algorithm>
#include <cmath>

namespace orthoflow::drivers::kinect {

namespace {

// Depth in mm of raw disparity @p raw, cut at DEPTH_MAX_MM: the value every table holds.
double table_mm(std::uint16_t raw, const DisparityModel& model) noexcept {
  const double z = disparity_to_mm(static_cast<double>(raw), model);
  return (z > 0.0 && z <= DEPTH_MAX_MM) ? z : 0.0;
}

}  // namespace

DisparityModel disparity_model(const Calibration& calibration) noexcept {
  const ZeroPlane& zp = calibration.zero_plane;
  return {static_cast<double>(calibration.const_shift),
          static_cast<double>(zp.reference_distance_mm),
          static_cast<double>(zp.reference_pixel_size_mm),
          static_cast<double>(zp.dcmos_emitter_dist_cm)};
}

double disparity_to_mm(double raw, const DisparityModel& model) noexcept {
  if (raw >= RAW_NO_READING) return 0.0;
  const double ref_dist = model.reference_distance_mm;
  const double b = model.emitter_dist_cm;
  const double x = (raw - 4.0 * model.const_shift) / 4.0 - 0.375;
  const double m = x * model.reference_pixel_size_mm;
  if (m >= b) return 0.0;  // at and past the pole the formula explodes, then goes negative
  return 10.0 * (m * ref_dist / (b - m) + ref_dist);
}

double mm_to_disparity(double mm, const DisparityModel& model) noexcept {
  // disparity_to_mm solved for raw: m = b - 10 ref_dist b / z, raw = 4 (m / ref_pix + 0.375) + 4
  // const_shift.
  const double b = model.emitter_dist_cm;
  const double m = b - 10.0 * model.reference_distance_mm * b / mm;
  const double x = m / model.reference_pixel_size_mm;
  return 4.0 * (x + 0.375) + 4.0 * model.const_shift;
}

std::uint16_t mm_to_raw(double mm, const DisparityModel& model) noexcept {
  if (!std::isfinite(mm) || mm <= 0.0) return RAW_NO_READING;
  const double raw = std::round(mm_to_disparity(mm, model));
  return static_cast<std::uint16_t>(std::clamp(raw, 0.0, double{RAW_NO_READING - 1}));
}

double raw_to_mm(std::uint16_t raw, const Calibration& calibration) noexcept {
  return table_mm(raw, disparity_model(calibration));
}

DepthTableMm make_depth_table_mm(const Calibration& calibration) noexcept {
  const DisparityModel model = disparity_model(calibration);
  DepthTableMm table{};
  for (std::size_t raw = 0; raw < table.size(); ++raw) {
    table[raw] = static_cast<std::uint16_t>(table_mm(static_cast<std::uint16_t>(raw), model));
  }
  return table;
}

void make_depth_table_m(const Calibration& calibration,
                        std::span<float, kernels::DISPARITY_TABLE_SIZE> table_m) noexcept {
  make_depth_table_m(disparity_model(calibration), table_m);
}

void make_depth_table_m(const DisparityModel& model,
                        std::span<float, kernels::DISPARITY_TABLE_SIZE> table_m) noexcept {
  for (std::size_t raw = 0; raw < table_m.size(); ++raw) {
    table_m[raw] = static_cast<float>(table_mm(static_cast<std::uint16_t>(raw), model) / 1000.0);
  }
}

kernels::DepthCamera depth_camera(const Calibration& calibration) noexcept {
  const double f = calibration.zero_plane.reference_distance_mm /
                   (2.0 * calibration.zero_plane.reference_pixel_size_mm);
  kernels::DepthCamera camera;
  camera.fx = static_cast<float>(f);
  camera.fy = static_cast<float>(f);
  camera.cx = 319.5F;
  camera.cy = 239.5F;
  return camera;
}

}  // namespace orthoflow::drivers::kinect
