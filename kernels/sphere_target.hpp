#pragma once
/// @file
/// @brief A ball of known radius in an organized depth frame: the calibration target of eye-to-hand
/// calibration (docs/MANIPULATION.md section 2, "target centres"). Every pixel with a surface
/// normal votes for the centre a ball of that radius behind it would have (its point minus radius
/// times its normal, the normal turned toward the sensor); the votes of a ball's visible cap fall
/// together, those of the table, of boxes and of cylinders of another radius spread. The cell with
/// the most votes (with its 26 neighbours) seeds a least-squares fit of a sphere of that radius to
/// the pixels within `tolerance` of it on the side facing the sensor (Gauss-Newton); the SEEDS
/// best-voted cells apart from each other are each fitted, and the fit with the most pixels among
/// those accepted wins; two accepted fits a radius apart refuse the frame (which one is the ball is
/// not certain: choose a ball whose radius nothing else in view has). Accepted only when enough
/// pixels fit, their residual is small and they form a cap facing the sensor. Not on the frame
/// path: allocates its vote table once, then nothing.
#include <array>
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "core/result.hpp"
#include "kernels/organized_normals.hpp"
#include "kernels/point_cloud.hpp"

namespace orthoflow::kernels {

struct SphereTargetParams {
  float radius = 0.05F;            ///< the ball's radius, metres
  float tolerance = 0.006F;        ///< a pixel fits when its distance to the surface is within this
  std::uint32_t min_pixels = 150;  ///< pixels that must fit
  /// The radius fitted freely to those pixels must be within this of `radius` (the arm's rounded
  /// joints and a ball of another size fit a sphere of the radius sought loosely, but their own
  /// radius differs). Metres.
  float radius_tolerance = 0.003F;
  /// The fitted pixels' mean direction from the centre must point at the sensor within this cone
  /// (a cap seen from the sensor; a cylinder of the same radius fits a band, off to one side
  /// when the seed is off its axis). Degrees.
  float max_cap_tilt_deg = 30.0F;
  float min_range = 0.3F, max_range = 3.0F;  ///< pixels beyond these depths do not vote (metres)
  NormalParams normals{};
};

/// @brief The ball found.
struct SphereTarget {
  std::array<double, 3> centre{};  ///< sensor frame, metres
  std::size_t pixels = 0;          ///< pixels that fit
  double rms = 0.0;                ///< their distance to the sphere, metres
  std::size_t votes = 0;           ///< votes of the seed's 27 cells
  int iterations = 0;
};

/// @brief Finds a ball of a given radius in organized frames (one instance per thread).
class SphereTargetFinder {
 public:
  /// @brief Vote cells fitted per frame (the arm's rounded joints vote too).
  static constexpr std::size_t SEEDS = 8;
  /// @brief Sized for frames of up to @p max_points pixels.
  explicit SphereTargetFinder(std::size_t max_points);
  /// @brief The ball in @p cloud, or why none was accepted (no pixel with a normal, too few pixels
  /// fit, residual too large, a cap not facing the sensor). @pre cloud organized.
  [[nodiscard]] Result<SphereTarget, std::string> find(CloudView cloud,
                                                       const SphereTargetParams& params);

 private:
  std::vector<float> nx_, ny_, nz_;
  std::vector<std::uint32_t> near_;  // pixels near the seed being fitted
  std::vector<std::uint64_t> keys_;  // open addressing: vote cell keys (0 = empty)
  std::vector<std::uint32_t> counts_;
  std::vector<std::uint32_t> used_;  // slots filled this frame
};

}  // namespace orthoflow::kernels
