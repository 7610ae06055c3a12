// Test and benchmark support: a camera image (graphs::CameraImage) as a pinhole camera with focal
// length f (pixels) and principal point (cx, cy) sees a scene whose depth at pixel (i, j) is
// depth(i, j); no colour (callers fill rgb when they want it). Header-only.
#pragma once

#include <cstddef>
#include <cstdint>

#include "graphs/nodes/camera_tap.hpp"

namespace orthoflow::test {

template <class Depth>
graphs::CameraImage pinhole_image(std::uint32_t width, std::uint32_t height, double f, double cx,
                                  double cy, Depth depth) {
  graphs::CameraImage image;
  image.width = width;
  image.height = height;
  image.frame_id = 1;
  const std::size_t n = static_cast<std::size_t>(width) * height;
  image.x.resize(n);
  image.y.resize(n);
  image.z.resize(n);
  for (std::uint32_t j = 0; j < height; ++j) {
    for (std::uint32_t i = 0; i < width; ++i) {
      const std::size_t k = static_cast<std::size_t>(j) * width + i;
      const float z = depth(i, j);
      image.z[k] = z;
      image.x[k] = static_cast<float>((i - cx) / f * z);
      image.y[k] = static_cast<float>((j - cy) / f * z);
    }
  }
  return image;
}

}  // namespace orthoflow::test
