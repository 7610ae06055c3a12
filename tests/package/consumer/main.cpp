// A user's program built against an installed orthoflow.
#include <cmath>
#include <cstdio>

#include "kernels/cloud_stats.hpp"
#include "kernels/point_cloud.hpp"

int main() {
  orthoflow::kernels::PointCloud cloud;
  cloud.resize(2, 2);
  const float xs[] = {0.0F, 1.0F, NAN, 2.0F};
  for (int i = 0; i < 4; ++i) {
    cloud.x()[static_cast<std::size_t>(i)] = xs[i];
  }
  const auto stats = orthoflow::kernels::cloud_stats(cloud.points());
  std::printf("consumer: %zu finite points, x in [%g, %g]\n", stats.finite, static_cast<double>(stats.min[0]),
              static_cast<double>(stats.max[0]));
  return stats.finite == 3 ? 0 : 1;
}
