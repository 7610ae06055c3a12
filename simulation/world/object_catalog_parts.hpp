#pragma once
/// @file
/// @brief (internal) The helpers the object recipes are written with, shared by object_catalog.cpp
/// (the original twelve categories) and object_catalog_household.cpp (the categories added for the
/// object-view evaluation, issue 8).
#include <cmath>

#include "core/assert.hpp"
#include "core/rng.hpp"
#include "simulation/world/object_catalog.hpp"

namespace orthoflow::simulation {

/// @brief Appends solids to a model's part list.
/// @pre the recipe adds at most MAX_PRIMITIVES parts (enforced). Not thread-safe on one model.
struct ObjectBuilder {
  ObjectModel& m;
  /// @brief Appends @p p. @pre fewer than MAX_PRIMITIVES parts so far.
  void add(const Primitive& p) {
    OF_ENFORCE(m.part_count < MAX_PRIMITIVES, "object recipe: more than MAX_PRIMITIVES parts");
    m.parts[m.part_count++] = p;
  }
  /// @brief A frustum standing on the axis at height @p z: radii @p r0 (bottom), @p r1 (top),
  /// height @p h.
  void frustum(double z, double r0, double r1, double h, bool open_top = false) {
    add(Primitive{PrimitiveKind::FRUSTUM, {0, 0, z}, {r0, r1, h}, open_top});
  }
  /// @brief An ellipsoid, only its part with z in [@p clip_min, @p clip_max] (an open shell when
  /// clipped).
  void ellipsoid(Vec3 c, Vec3 radii, double clip_min = -1e9, double clip_max = 1e9) {
    add(Primitive{PrimitiveKind::ELLIPSOID, c, radii, false, clip_min, clip_max});
  }
  /// @brief An axis-aligned box: centre and half extents.
  void box(Vec3 c, Vec3 half) { add(Primitive{PrimitiveKind::BOX, c, half}); }
  /// @brief A tube of @p n small spheres along a circular arc in the xz plane around @p c, angles
  /// from +z towards +x (mug and teapot handles, spouts, bucket bails). @pre n >= 2.
  void arc(Vec3 c, double radius, double tube, double from, double to, int n) {
    for (int i = 0; i < n; ++i) {
      const double a = from + (to - from) * i / (n - 1);
      ellipsoid({c[0] + radius * std::sin(a), c[1], c[2] + radius * std::cos(a)},
                {tube, tube, tube});
    }
  }
};

/// @brief Adds the parts of one instance of a household category (GLASS and after) drawn from @p r.
/// @pre @p c is not one of the original twelve categories. Deterministic in @p r's state.
void build_household(ObjectBuilder& b, core::Rng& r, Category c);

}  // namespace orthoflow::simulation
