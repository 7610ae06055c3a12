#pragma once
/// @file
/// @brief Analytic ray casting against the solids the synthetic objects are built from: frusta
/// (cylinders when both radii agree), ellipsoids clipped to a height band (bowls, spoon bowls) and
/// boxes, all in an object frame whose z axis is the table normal.
#include <array>
#include <cstdint>

namespace orthoflow::simulation {

using Vec3 = std::array<double, 3>;

inline Vec3 operator+(const Vec3& a, const Vec3& b) {
  return {a[0] + b[0], a[1] + b[1], a[2] + b[2]};
}
inline Vec3 operator-(const Vec3& a, const Vec3& b) {
  return {a[0] - b[0], a[1] - b[1], a[2] - b[2]};
}
inline Vec3 operator*(double s, const Vec3& a) { return {s * a[0], s * a[1], s * a[2]}; }
inline double dot(const Vec3& a, const Vec3& b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }
inline Vec3 cross(const Vec3& a, const Vec3& b) {
  return {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
}

enum class PrimitiveKind : std::uint8_t { FRUSTUM, ELLIPSOID, BOX };

/// @brief One solid in object coordinates (metres).
/// FRUSTUM: base centre `center`, axis +z, `size` = (bottom radius, top radius, height); `open_top`
/// leaves the top disk out and keeps the inner wall visible (mugs). ELLIPSOID: centre and radii;
/// only hits with z in [clip_min, clip_max] (object frame) count, which makes open shells.
/// BOX: centre and half extents, axis-aligned in the object frame.
struct Primitive {
  PrimitiveKind kind = PrimitiveKind::BOX;
  Vec3 center{};
  Vec3 size{};
  bool open_top = false;
  double clip_min = -1e9;
  double clip_max = 1e9;
};

/// @brief The nearest intersection: ray parameter and (unnormalised) surface normal.
struct Hit {
  double t = 1e300;
  Vec3 normal{};
  [[nodiscard]] bool found() const noexcept { return t < 1e299; }
};

/// @brief Intersects the ray o + t d (t > t_min) with @p p; keeps the hit only if nearer than @p
/// best.
/// @return true when @p best was updated.
bool intersect(const Primitive& p, const Vec3& o, const Vec3& d, double t_min, Hit& best) noexcept;

/// @brief Intersects the ray o + t d (t > t_min, d of any non-zero length) with the capsule around
/// the segment [a, b] of radius @p r (the entry point: rays starting inside find nothing); keeps
/// the hit only if nearer than @p best. @return true when @p best was updated.
bool intersect_capsule(const Vec3& a, const Vec3& b, double r, const Vec3& o, const Vec3& d,
                       double t_min, Hit& best) noexcept;

}  // namespace orthoflow::simulation
