// The ray-primitive intersections of the synthetic scenes (simulation/world/shape_primitives.hpp)
// against hand-computed hits: frusta and cylinders, clipped ellipsoids, boxes and capsules. The
// other building blocks: synthetic_model_test.cpp.
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "simulation/world/shape_primitives.hpp"

namespace orthoflow::simulation {
namespace {

// ---- Ray-primitive intersections
// --------------------------------------------------------------------

Hit cast(const Primitive& p, const Vec3& o, const Vec3& d) {
  Hit h;
  intersect(p, o, d, 1e-9, h);
  return h;
}

Vec3 unit(const Vec3& v) { return (1.0 / std::sqrt(dot(v, v))) * v; }

void expect_hit(const Hit& h, double t, const Vec3& normal, const std::string& what) {
  ASSERT_TRUE(h.found()) << what;
  EXPECT_NEAR(h.t, t, 1e-12) << what;
  const Vec3 n = unit(h.normal);
  for (std::size_t k = 0; k < 3; ++k) {
    EXPECT_NEAR(n[k], normal[k], 1e-9) << what << " normal[" << k << "]";
  }
}

TEST(ShapePrimitives, CylinderConeAndOpenTopHitsWhereExpected) {
  const Primitive cylinder{PrimitiveKind::FRUSTUM, {0, 0, 0}, {0.05, 0.05, 0.1}};
  expect_hit(cast(cylinder, {1, 0, 0.05}, {-1, 0, 0}), 0.95, {1, 0, 0}, "cylinder side");
  expect_hit(cast(cylinder, {0.01, 0, 1}, {0, 0, -1}), 0.9, {0, 0, 1}, "cylinder top");
  expect_hit(cast(cylinder, {0, 0.02, -1}, {0, 0, 1}), 1.0, {0, 0, -1}, "cylinder bottom");
  EXPECT_FALSE(cast(cylinder, {1, 0, 0.15}, {-1, 0, 0}).found()) << "passes above";
  EXPECT_FALSE(cast(cylinder, {1, 0.06, 0.05}, {-1, 0, 0}).found()) << "passes beside";
  Primitive mug = cylinder;
  mug.open_top = true;  // looking in: the inside of the bottom, no lid
  expect_hit(cast(mug, {0.01, 0, 1}, {0, 0, -1}), 1.0, {0, 0, -1}, "open top");
  // Looking in at a slant: the inner wall at x = -0.05 on the far side.
  expect_hit(cast(mug, {0.05, 0, 0.19}, {-1, 0, -1}), 0.1, {-1, 0, 0}, "inner wall");
  const Primitive cone{PrimitiveKind::FRUSTUM, {0, 0, 0.2}, {0.1, 0.0, 0.1}};
  const double s = std::sqrt(0.5);
  expect_hit(cast(cone, {1, 0, 0.25}, {-1, 0, 0}), 0.95, {s, 0, s}, "cone side at half height");
  EXPECT_FALSE(cast(cone, {1, 0, 0.31}, {-1, 0, 0}).found()) << "above the apex";
}

TEST(ShapePrimitives, ClippedEllipsoidIsAnOpenShell) {
  // A bowl: the lower half of an ellipsoid, open at the top.
  const Primitive bowl{PrimitiveKind::ELLIPSOID, {0, 0, 0.1}, {0.1, 0.1, 0.05}, false, 0.0, 0.1};
  expect_hit(cast(bowl, {0, 0, 1}, {0, 0, -1}), 0.95, {0, 0, -1}, "inside of the bottom");
  expect_hit(cast(bowl, {0, 0, -1}, {0, 0, 1}), 1.05, {0, 0, -1}, "outside of the bottom");
  expect_hit(cast(bowl, {1, 0, 0.1}, {-1, 0, 0}), 0.9, {1, 0, 0}, "rim, outside");
  EXPECT_FALSE(cast(bowl, {1, 0, 0.12}, {-1, 0, 0}).found()) << "above the clip height";
  const Primitive ball{PrimitiveKind::ELLIPSOID, {0.3, 0, 0}, {0.02, 0.02, 0.02}};
  expect_hit(cast(ball, {0.3, -1, 0}, {0, 1, 0}), 0.98, {0, -1, 0}, "sphere");
}

TEST(ShapePrimitives, BoxFacesAndNearestHitKeeping) {
  const Primitive box{PrimitiveKind::BOX, {0, 0, 0.05}, {0.1, 0.05, 0.05}};
  expect_hit(cast(box, {0, -1, 0.05}, {0, 1, 0}), 0.95, {0, -1, 0}, "-y face");
  expect_hit(cast(box, {2, 0, 0.02}, {-1, 0, 0}), 1.9, {1, 0, 0}, "+x face");
  expect_hit(cast(box, {0.05, 0.01, 1}, {0, 0, -2}), 0.45, {0, 0, 1},
             "top, unnormalised direction");
  EXPECT_FALSE(cast(box, {0, -1, 0.2}, {0, 1, 0}).found());
  // A hit farther than the one already kept leaves it alone.
  Hit best;
  best.t = 0.5;
  EXPECT_FALSE(intersect(box, {0, -1, 0.05}, {0, 1, 0}, 1e-9, best));
  EXPECT_EQ(best.t, 0.5);
  EXPECT_TRUE(intersect(box, {0, -1, 0.05}, {0, 1, 0}, 1e-9, best = Hit{}));
  // Hits behind t_min do not count.
  Hit behind;
  EXPECT_FALSE(intersect(box, {0, -1, 0.05}, {0, 1, 0}, 1.0, behind));
}

TEST(ShapePrimitives, CapsuleSideCapsAndMisses) {
  // A capsule along x from (0,0,1) to (0.4,0,1), radius 0.05, seen along +z from the origin.
  const Vec3 a{0, 0, 1}, b{0.4, 0, 1};
  Hit h;
  ASSERT_TRUE(intersect_capsule(a, b, 0.05, {0.2, 0, 0}, {0, 0, 1}, 1e-9, h));
  EXPECT_NEAR(h.t, 0.95, 1e-12) << "the side, straight on";
  EXPECT_NEAR(h.normal[2] / std::sqrt(dot(h.normal, h.normal)), -1.0, 1e-12);
  Hit cap;
  ASSERT_TRUE(intersect_capsule(a, b, 0.05, {-0.03, 0, 0}, {0, 0, 2}, 1e-9, cap))
      << "beyond the segment's end: the end sphere (any ray length)";
  EXPECT_NEAR(cap.t * 2, 1.0 - std::sqrt(0.05 * 0.05 - 0.03 * 0.03), 1e-12);
  Hit along;
  ASSERT_TRUE(intersect_capsule(a, b, 0.05, {-1, 0, 1}, {1, 0, 0}, 1e-9, along))
      << "along the axis: the near end's sphere";
  EXPECT_NEAR(along.t, 0.95, 1e-12);
  Hit miss;
  EXPECT_FALSE(intersect_capsule(a, b, 0.05, {0.2, 0.06, 0}, {0, 0, 1}, 1e-9, miss));
  EXPECT_FALSE(intersect_capsule(a, b, 0.05, {0.46, 0, 0}, {0, 0, 1}, 1e-9, miss));
  EXPECT_FALSE(intersect_capsule(a, b, 0.05, {0.2, 0, 1}, {0, 0, 1}, 1e-9, miss)) << "from inside";
  Hit nearer;
  nearer.t = 0.5;
  EXPECT_FALSE(intersect_capsule(a, b, 0.05, {0.2, 0, 0}, {0, 0, 1}, 1e-9, nearer))
      << "a nearer hit is kept";
  Hit sphere;
  ASSERT_TRUE(intersect_capsule(a, a, 0.05, {0, 0, 0}, {0, 0, 1}, 1e-9, sphere)) << "a == b";
  EXPECT_NEAR(sphere.t, 0.95, 1e-12);
}

}  // namespace
}  // namespace orthoflow::simulation
