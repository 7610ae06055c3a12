// "Up" from the accelerometer (drivers/kinect/kinect_gravity.hpp).
#include "drivers/kinect/kinect_gravity.hpp"

#include <cmath>

namespace orthoflow::drivers::kinect {

std::optional<std::array<float, 3>> up_from_accel(std::int16_t x, std::int16_t y,
                                                  std::int16_t z) noexcept {
  constexpr double COUNTS_PER_G = 819.0;  // Kionix KXSD9 (KINECT_V1.md 11)
  const double ux = -double(x), uy = -double(y), uz = double(z);
  const double norm = std::sqrt(ux * ux + uy * uy + uz * uz);
  if (!(std::fabs(norm / COUNTS_PER_G - 1.0) <= GRAVITY_TOLERANCE_G)) return std::nullopt;
  return std::array<float, 3>{float(ux / norm), float(uy / norm), float(uz / norm)};
}

}  // namespace orthoflow::drivers::kinect
