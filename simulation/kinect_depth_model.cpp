#include "simulation/kinect_depth_model.hpp"

namespace orthoflow::simulation {
namespace {

// Constants of libfreenect's registration.c (KINECT_V1.md 8.2).
constexpr double COEFF = 4.0;
constexpr double SCALE = 10.0;
constexpr double OFFSET = 0.375;

}  // namespace

double raw_to_depth_m(double raw, const KinectDepthParams& p) noexcept {
  if (raw >= KINECT_NO_READING) { return 0.0; }
  const double x = (raw - COEFF * p.const_shift) / COEFF - OFFSET;
  const double m = x * p.ref_pix_mm;
  const double b = p.emitter_dist_cm;
  if (m >= b) { return 0.0; }  // past the pole the formula goes negative
  const double z_mm = SCALE * p.ref_dist_mm * b / (b - m);
  return z_mm / 1000.0;
}

double depth_to_raw(double depth_m, const KinectDepthParams& p) noexcept {
  const double b = p.emitter_dist_cm;
  const double m = b - SCALE * p.ref_dist_mm * b / (depth_m * 1000.0);
  const double x = m / p.ref_pix_mm;
  return COEFF * (x + OFFSET) + COEFF * p.const_shift;
}

double depth_step_m(double depth_m, const KinectDepthParams& p) noexcept {
  // z_mm = K / (b - m), K = SCALE ref_dist b, so dz/dm = z_mm^2 / K and dm/draw = ref_pix / COEFF.
  const double k = SCALE * p.ref_dist_mm * p.emitter_dist_cm;
  const double z_mm = depth_m * 1000.0;
  return z_mm * z_mm / k * p.ref_pix_mm / COEFF / 1000.0;
}

double depth_error_bound_m(double depth_m, const KinectDepthParams& p) noexcept {
  // The error in raw units is at most 6 sigma_raw + 0.5; the step grows within that span, hence the
  // step is taken at the far end of it (5 % margin).
  const double raw_error = 6.0 * p.sigma_raw + 0.5;
  return 1.05 * raw_error * depth_step_m(depth_m * 1.05, p);
}

DepthTable make_depth_table(const KinectDepthParams& p) noexcept {
  DepthTable table{};
  for (std::size_t raw = 0; raw < table.size(); ++raw) {
    table[raw] = static_cast<float>(raw_to_depth_m(static_cast<double>(raw), p));
  }
  return table;
}

}  // namespace orthoflow::simulation
