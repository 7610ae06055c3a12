#include "drivers/kinect_depth.hpp"

namespace orthoflow::drivers::kinect {

double raw_to_mm(std::uint16_t raw, const Calibration& calibration) noexcept {
  if (raw >= RAW_NO_READING) return 0.0;
  const ZeroPlane& zp = calibration.zero_plane;
  const double ref_dist = zp.reference_distance_mm;
  const double b = zp.dcmos_emitter_dist_cm;
  const double x = (static_cast<double>(raw) - 4.0 * calibration.const_shift) / 4.0 - 0.375;
  const double m = x * zp.reference_pixel_size_mm;
  if (m >= b) return 0.0;  // at and past the pole the formula explodes, then goes negative
  const double z = 10.0 * (m * ref_dist / (b - m) + ref_dist);
  return (z > 0.0 && z <= DEPTH_MAX_MM) ? z : 0.0;
}

DepthTableMm make_depth_table_mm(const Calibration& calibration) noexcept {
  DepthTableMm table{};
  for (std::size_t raw = 0; raw < table.size(); ++raw) {
    table[raw] =
        static_cast<std::uint16_t>(raw_to_mm(static_cast<std::uint16_t>(raw), calibration));
  }
  return table;
}

void make_depth_table_m(const Calibration& calibration,
                        std::span<float, kernels::DISPARITY_TABLE_SIZE> table_m) noexcept {
  for (std::size_t raw = 0; raw < table_m.size(); ++raw) {
    table_m[raw] =
        static_cast<float>(raw_to_mm(static_cast<std::uint16_t>(raw), calibration) / 1000.0);
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
