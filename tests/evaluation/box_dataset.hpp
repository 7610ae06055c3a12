#pragma once
// A small dataset on disk for the file-level tests: category k is a box of its own proportions,
// each view 400 seeded points on the box's surface, rotated about the vertical by a per-view angle.
// Written as DIR/box<k>/inst<i>/view<v>.pcd under a directory unique to the test process.
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <string>

#include "core/rng.hpp"
#include "formats/pcd_io.hpp"

namespace orthoflow::evaluation::testing {

inline std::filesystem::path unique_dir(const std::string& name) {
  const std::filesystem::path d = std::filesystem::temp_directory_path() /
                                  ("orthoflow_eval_" + name + "_" + std::to_string(::getpid()));
  std::filesystem::remove_all(d);
  std::filesystem::create_directories(d);
  return d;
}

inline kernels::PointCloud box_view(int category, int instance, int view) {
  core::Rng rng(static_cast<std::uint64_t>(category * 1000 + instance * 100 + view + 1));
  const double hx = 0.02 + 0.03 * category + 0.002 * instance, hy = 0.03,
               hz = 0.02 + 0.015 * (category % 3);
  const double angle = 0.6 * view + 0.3 * instance;
  kernels::PointCloud cloud;
  cloud.resize_unorganized(400);
  for (std::size_t i = 0; i < 400; ++i) {
    // A point on one of the three faces the camera sees (+x, +y, +z), uniform on each.
    const auto face = rng.below(3);
    double p[3] = {rng.uniform(-hx, hx), rng.uniform(-hy, hy), rng.uniform(-hz, hz)};
    p[face] = face == 0 ? hx : face == 1 ? hy : hz;
    cloud.x()[i] = static_cast<float>(std::cos(angle) * p[0] - std::sin(angle) * p[1]);
    cloud.y()[i] = static_cast<float>(std::sin(angle) * p[0] + std::cos(angle) * p[1]);
    cloud.z()[i] = static_cast<float>(p[2] + 1.0);
  }
  return cloud;
}

/// Writes categories x instances x views box views under @p root.
inline void write_box_dataset(const std::filesystem::path& root, int categories, int instances,
                              int views) {
  for (int c = 0; c < categories; ++c) {
    for (int i = 0; i < instances; ++i) {
      const std::filesystem::path dir =
          root / ("box" + std::to_string(c)) / ("inst" + std::to_string(i));
      std::filesystem::create_directories(dir);
      for (int v = 0; v < views; ++v) {
        (void)formats::write_pcd(box_view(c, i, v), dir / ("view" + std::to_string(v) + ".pcd"),
                                 formats::PcdEncoding::BINARY);
      }
    }
  }
}

}  // namespace orthoflow::evaluation::testing
