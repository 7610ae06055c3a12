#pragma once
// A seeded mug-like object view for the spin-image comparisons with PCL (tests/kernels and
// bench/vs_pcl share it): the near half of a cylinder wall, its rim and a handle-like lump.
#include <cmath>
#include <cstdint>
#include <memory>
#include <random>

#include <pcl/point_cloud.h>
#include <pcl/point_types.h>

namespace orthoflow::bench {

// A mug-like view: the near half of a cylinder wall (radius 4 cm, height 10 cm), its rim and a
// handle-like lump, with 1 mm noise; seeded.
inline pcl::PointCloud<pcl::PointXYZ>::Ptr mug_view(std::uint32_t seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> u(0.0F, 1.0F);
  std::normal_distribution<float> noise(0.0F, 0.001F);
  auto cloud = std::make_shared<pcl::PointCloud<pcl::PointXYZ>>();
  for (int i = 0; i < 2500; ++i) {
    const float a = 3.14159F * u(rng), h = 0.1F * u(rng);
    cloud->push_back(
        {0.04F * std::cos(a) + noise(rng), -0.04F * std::sin(a) + noise(rng), h + noise(rng)});
  }
  for (int i = 0; i < 400; ++i) {
    const float a = 6.2832F * u(rng);
    const float r = 0.035F + 0.005F * u(rng);
    cloud->push_back({r * std::cos(a), r * std::sin(a), 0.1F + noise(rng)});
  }
  for (int i = 0; i < 300; ++i) {
    const float a = 3.14159F * u(rng);
    cloud->push_back({0.05F + 0.02F * std::sin(a) + noise(rng), noise(rng) + 0.004F * u(rng),
                      0.05F + 0.03F * std::cos(a)});
  }
  return cloud;
}

}  // namespace orthoflow::bench
