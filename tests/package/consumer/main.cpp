// A user's program built against an installed orthoflow: kernels and formats only (the PCD round
// trip pulls in liblzf, formats' private dependency, at link time).
#include <cmath>
#include <cstdio>

#include "formats/pcd_io.hpp"
#include "kernels/cloud_stats.hpp"
#include "kernels/point_cloud.hpp"

int main() {
  orthoflow::kernels::PointCloud cloud;
  cloud.resize(2, 2);
  const float xs[] = {0.0F, 1.0F, NAN, 2.0F};
  for (int i = 0; i < 4; ++i) { cloud.x()[static_cast<std::size_t>(i)] = xs[i]; }
  const auto stats = orthoflow::kernels::cloud_stats(cloud.points());
  std::printf("consumer: %zu finite points, x in [%g, %g]\n", stats.finite,
              static_cast<double>(stats.min[0]), static_cast<double>(stats.max[0]));
  const std::string bytes =
      orthoflow::formats::encode_pcd(cloud, orthoflow::formats::PcdEncoding::BINARY_COMPRESSED);
  const auto back = orthoflow::formats::read_pcd_buffer(bytes);
  if (!back) return 1;
  std::printf("consumer: %zu points read back from a binary_compressed PCD\n", back->size());
  return stats.finite == 3 && back->size() == 4 ? 0 : 1;
}
