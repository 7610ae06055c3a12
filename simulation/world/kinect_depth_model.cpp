// The simulator's depth model over the driver's formula (drivers/kinect/kinect_depth.hpp): the
// conversions and the table are the driver's; the step and the error bound are the noise model's.
#include "simulation/world/kinect_depth_model.hpp"

namespace orthoflow::simulation {
namespace {

// Constants of libfreenect's registration.c (KINECT_V1.md 8.2) the step derivation uses.
constexpr double COEFF = 4.0;
constexpr double SCALE = 10.0;

}  // namespace

drivers::kinect::DisparityModel disparity_model(const KinectDepthParams& p) noexcept {
  return {p.const_shift, p.ref_dist_mm, p.ref_pix_mm, p.emitter_dist_cm};
}

double raw_to_depth_m(double raw, const KinectDepthParams& p) noexcept {
  return drivers::kinect::disparity_to_mm(raw, disparity_model(p)) / 1000.0;
}

double depth_to_raw(double depth_m, const KinectDepthParams& p) noexcept {
  return drivers::kinect::mm_to_disparity(depth_m * 1000.0, disparity_model(p));
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
  drivers::kinect::make_depth_table_m(disparity_model(p), table);
  return table;
}

}  // namespace orthoflow::simulation
