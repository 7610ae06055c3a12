#pragma once
/// @file
/// @brief The inputs of issue 50 item 3 on which the tabletop graph must hold its deadline, as
/// organized 640x480 Kinect-like clouds (sensor frame: x right, y down, z forward; NaN where the
/// sensor has no reading), drawn deterministically from a seed so that a sequence of frames
/// differs only in its noise:
/// - NOISE: every pixel a random depth in [0.5, 4] m (a sensor that has gone mad);
/// - WALL: a flat wall 1.5 m ahead, facing the camera, with depth noise;
/// - INVALID: no reading anywhere;
/// - HAND: a hand at the lens: most pixels closer than the sensor's 0.45 m minimum (no reading),
///   the hand's rim at 0.45-0.6 m, the room behind it at 2.5 m in one corner;
/// - PERSON: a person at a desk seen from the side of the desk: a back wall at 3 m, a torso, a
///   head and two arms in front of it, the desk's front panel below them, no level support;
/// - HEAP: a table heaped with as many of 60 synthetic objects as fit, touching in pairs
///   (simulation::make_scene + render_scene, with ground-truth labels).
/// For the benchmarks (bench/vs_pcl/graph_latency_vs_pcl.cpp) and the tests of the objects node's
/// budget. Header-only.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <string_view>

#include "core/rng.hpp"
#include "kernels/point_cloud.hpp"
#include "simulation/world/synthetic_scene.hpp"

namespace orthoflow::test {

enum class Hostile { NOISE, WALL, INVALID, HAND, PERSON, HEAP };

inline constexpr Hostile HOSTILE_INPUTS[] = {Hostile::NOISE, Hostile::WALL,   Hostile::INVALID,
                                             Hostile::HAND,  Hostile::PERSON, Hostile::HEAP};

inline std::string_view hostile_name(Hostile h) noexcept {
  switch (h) {
    case Hostile::NOISE:
      return "noise";
    case Hostile::WALL:
      return "wall";
    case Hostile::INVALID:
      return "invalid";
    case Hostile::HAND:
      return "hand";
    case Hostile::PERSON:
      return "person";
    case Hostile::HEAP:
      return "heap60";
  }
  return "?";
}

namespace detail {

constexpr double FX = 575.8, CX = 319.5, CY = 239.5;  // the simulated Kinect's intrinsics
constexpr std::uint32_t W = 640, H = 480;

/// Depth of the person-at-a-desk scene along the ray through pixel (i, j), or NaN.
inline double person_depth(double u, double v) {
  // Ray direction (u, v, 1); shapes as boxes / spheres in camera coordinates (metres).
  double best = 3.0;                                                      // the back wall
  auto box = [&](double x0, double x1, double y0, double y1, double z) {  // a camera-facing slab
    const double x = u * z, y = v * z;
    if (x >= x0 && x <= x1 && y >= y0 && y <= y1) best = std::min(best, z);
  };
  box(-0.22, 0.22, -0.35, 0.35, 1.4);   // torso
  box(-0.40, -0.24, -0.30, 0.25, 1.3);  // left arm
  box(0.24, 0.40, -0.30, 0.25, 1.25);   // right arm, nearer
  box(-0.9, 0.9, 0.30, 1.2, 1.1);       // the desk's front panel (vertical)
  // head: a sphere of radius 0.11 centred at (0, -0.5, 1.45)
  const double n2 = u * u + v * v + 1.0, b = (0.0 * u - 0.5 * v + 1.45);
  const double c = 0.25 + 1.45 * 1.45 - 0.11 * 0.11, disc = b * b - n2 * c;
  if (disc >= 0.0) best = std::min(best, (b - std::sqrt(disc)) / n2);
  return best;
}

}  // namespace detail

/// @brief Frame @p k of input @p h; the noise comes from seed + k. HEAP renders its scene (seed)
/// with sensor noise drawn from seed + k. Allocates.
inline kernels::PointCloud hostile_frame(Hostile h, std::uint64_t seed, std::uint64_t k) {
  using namespace detail;
  kernels::PointCloud c;
  core::Rng rng(seed * 1000003ULL + k);
  if (h == Hostile::HEAP) {
    simulation::SceneConfig config;
    config.objects = 60;
    config.touching = true;
    const auto scene = simulation::make_scene(config, seed);
    simulation::render_scene(scene, {}, rng, c);
    return c;
  }
  c.resize(W, H);
  const float nan = std::numeric_limits<float>::quiet_NaN();
  for (std::uint32_t j = 0; j < H; ++j) {
    for (std::uint32_t i = 0; i < W; ++i) {
      const double u = (i - CX) / FX, v = (j - CY) / FX;
      double z = nan;
      switch (h) {
        case Hostile::NOISE:
          z = rng.uniform(0.5, 4.0);
          break;
        case Hostile::WALL:
          z = 1.5 + 0.003 * rng.normal();
          break;
        case Hostile::INVALID:
          break;
        case Hostile::HAND: {
          const double r = std::hypot((i - 300.0) / 420.0, (j - 260.0) / 330.0);
          if (r > 1.0 && i > 520 && j < 120)
            z = 2.5 + 0.02 * rng.normal();
          else if (r > 0.8 && r <= 1.0)
            z = 0.45 + 0.15 * (r - 0.8) / 0.2 + 0.002 * rng.normal();
          break;
        }
        case Hostile::PERSON:
          z = person_depth(u, v) + 0.004 * rng.normal();
          break;
        case Hostile::HEAP:
          break;
      }
      const std::size_t p = std::size_t{j} * W + i;
      c.x()[p] = static_cast<float>(u * z);
      c.y()[p] = static_cast<float>(v * z);
      c.z()[p] = static_cast<float>(z);
    }
  }
  return c;
}

}  // namespace orthoflow::test
