#pragma once
/// @file
/// @brief The Kinect v1 depth camera as a measurement model: intrinsics, the 11-bit disparity
/// ("raw") to millimetre conversion of libfreenect's registration.c (specs/KINECT_V1.md
/// section 8.2), its inverse, and the noise model used by the synthetic scenes. The conversion
/// and its table are the driver's own (drivers/kinect/kinect_depth.hpp, one formula for the
/// driver and the simulator); this header adds the noise model and the simulator's parameters.
///
/// Noise: Gaussian noise of sigma_raw (default 0.5 disparity units) is added to the continuous
/// disparity, which is then rounded to an integer. Because dZ/draw grows with Z^2, the depth noise
/// and the quantisation step grow with Z^2 (about 1.4 mm sigma and 2.9 mm steps at 1 m, 13 mm and
/// 26 mm at 3 m), as measured on real Kinects.
#include <array>
#include <cstdint>

#include "drivers/kinect/kinect_depth.hpp"

namespace orthoflow::simulation {

/// @brief Pinhole intrinsics of the 640x480 depth image (libfreenect's defaults, f = ref_dist / (2
/// ref_pix)).
struct DepthIntrinsics {
  double fx = 575.8;
  double fy = 575.8;
  double cx = 319.5;
  double cy = 239.5;
  std::uint32_t width = 640;
  std::uint32_t height = 480;
};

/// @brief The device parameters the raw-to-depth formula needs (typical values from KINECT_V1.md).
struct KinectDepthParams {
  double const_shift = 200.0;    ///< zero-plane shift
  double ref_dist_mm = 120.0;    ///< reference distance
  double ref_pix_mm = 0.1042;    ///< reference pixel size
  double emitter_dist_cm = 7.5;  ///< dcmos_emitter_dist: the projector-camera baseline
  double sigma_raw = 0.5;        ///< disparity noise (raw units) before rounding
  double min_range_m = 0.5;      ///< nearer returns are invalid
  double max_range_m = 4.0;      ///< farther returns are invalid
};

/// @brief Raw value meaning "no reading".
inline constexpr std::uint16_t KINECT_NO_READING = drivers::kinect::RAW_NO_READING;

/// @brief The driver's formula parameters of @p p (exact: both are double). @pre none.
[[nodiscard]] drivers::kinect::DisparityModel disparity_model(const KinectDepthParams& p) noexcept;

/// @brief Depth in metres of a raw disparity by registration.c's formula (the driver's
/// disparity_to_mm); 0 for 2047 and past the pole, no 10 m cut. @pre none.
[[nodiscard]] double raw_to_depth_m(double raw, const KinectDepthParams& p) noexcept;

/// @brief The continuous raw disparity that gives @p depth_m (the driver's mm_to_disparity).
/// @pre depth_m > 0.
[[nodiscard]] double depth_to_raw(double depth_m, const KinectDepthParams& p) noexcept;

/// @brief Depth difference (metres) between neighbouring raw values at depth @p depth_m: the
/// quantisation step, z^2 ref_pix / (4 * 10 ref_dist * baseline) (1000 mm/m folded in).
/// @pre depth_m > 0.
[[nodiscard]] double depth_step_m(double depth_m, const KinectDepthParams& p) noexcept;

/// @brief Hard bound on |measured - true| depth at @p depth_m for the synthetic noise: the normal
/// draw is an Irwin-Hall sum cut at 6 sigma, plus half a step of rounding. @pre depth_m > 0.
[[nodiscard]] double depth_error_bound_m(double depth_m, const KinectDepthParams& p) noexcept;

/// @brief The 2048-entry lookup table raw -> metres: the driver's table (make_depth_table_m), so
/// entry 2047, past-the-pole entries and depths beyond 10 m (libfreenect's cut) are 0.
using DepthTable = std::array<float, 2048>;
/// @brief The driver's depth table for @p p. @pre none.
[[nodiscard]] DepthTable make_depth_table(const KinectDepthParams& p) noexcept;

}  // namespace orthoflow::simulation
