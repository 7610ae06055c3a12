#include "simulation/world/shape_primitives.hpp"

#include <cmath>
#include <utility>

namespace orthoflow::simulation {
namespace {

bool take(double t, const Vec3& n, double t_min, Hit& best) {
  if (t > t_min && t < best.t) {
    best.t = t;
    best.normal = n;
    return true;
  }
  return false;
}

/// Real roots of a t^2 + 2 b t + c = 0 in ascending order; false when none.
bool roots(double a, double b, double c, double& t0, double& t1) {
  if (std::fabs(a) < 1e-18) {
    if (std::fabs(b) < 1e-18) { return false; }
    t0 = t1 = -c / (2.0 * b);
    return true;
  }
  const double disc = b * b - a * c;
  if (disc < 0.0) { return false; }
  const double s = std::sqrt(disc);
  t0 = (-b - s) / a;
  t1 = (-b + s) / a;
  if (t0 > t1) { std::swap(t0, t1); }
  return true;
}

bool disk(const Vec3& o, const Vec3& d, double z, double r, double t_min, double nz, Hit& best) {
  if (std::fabs(d[2]) < 1e-18 || r <= 0.0) { return false; }
  const double t = (z - o[2]) / d[2];
  const double x = o[0] + t * d[0];
  const double y = o[1] + t * d[1];
  return x * x + y * y <= r * r && take(t, {0.0, 0.0, nz}, t_min, best);
}

bool frustum(const Primitive& p, const Vec3& o_world, const Vec3& d, double t_min, Hit& best) {
  const Vec3 o = o_world - p.center;
  const double r0 = p.size[0], r1 = p.size[1], h = p.size[2];
  const double k = (r1 - r0) / h;
  const double a_ = r0 + k * o[2], b_ = k * d[2];
  double t0 = 0, t1 = 0;
  bool hit = false;
  if (roots(d[0] * d[0] + d[1] * d[1] - b_ * b_, o[0] * d[0] + o[1] * d[1] - a_ * b_,
            o[0] * o[0] + o[1] * o[1] - a_ * a_, t0, t1)) {
    for (double t : {t0, t1}) {
      const double z = o[2] + t * d[2];
      const double r = r0 + k * z;
      if (z < 0.0 || z > h || r < 0.0) { continue; }
      const Vec3 q = o + t * d;
      hit |= take(t, {q[0], q[1], -k * r}, t_min, best);
    }
  }
  hit |= disk(o, d, 0.0, r0, t_min, -1.0, best);
  if (!p.open_top) { hit |= disk(o, d, h, r1, t_min, 1.0, best); }
  return hit;
}

bool ellipsoid(const Primitive& p, const Vec3& o_world, const Vec3& d, double t_min, Hit& best) {
  const Vec3 o = o_world - p.center;
  const Vec3 os{o[0] / p.size[0], o[1] / p.size[1], o[2] / p.size[2]};
  const Vec3 ds{d[0] / p.size[0], d[1] / p.size[1], d[2] / p.size[2]};
  double t0 = 0, t1 = 0;
  if (!roots(dot(ds, ds), dot(os, ds), dot(os, os) - 1.0, t0, t1)) { return false; }
  bool hit = false;
  for (double t : {t0, t1}) {
    const Vec3 q = o + t * d;
    const double z = q[2] + p.center[2];
    if (z < p.clip_min || z > p.clip_max) { continue; }
    const Vec3 n{q[0] / (p.size[0] * p.size[0]), q[1] / (p.size[1] * p.size[1]),
                 q[2] / (p.size[2] * p.size[2])};
    hit |= take(t, n, t_min, best);
  }
  return hit;
}

bool box(const Primitive& p, const Vec3& o_world, const Vec3& d, double t_min, Hit& best) {
  const Vec3 o = o_world - p.center;
  double t_near = -1e300, t_far = 1e300;
  int axis = 0;
  double sign = 1.0;
  for (int i = 0; i < 3; ++i) {
    const auto k = static_cast<std::size_t>(i);
    if (std::fabs(d[k]) < 1e-18) {
      if (std::fabs(o[k]) > p.size[k]) { return false; }
      continue;
    }
    double ta = (-p.size[k] - o[k]) / d[k];
    double tb = (p.size[k] - o[k]) / d[k];
    const double s = ta < tb ? -1.0 : 1.0;  // the face the ray enters through
    if (ta > tb) { std::swap(ta, tb); }
    if (ta > t_near) {
      t_near = ta;
      axis = i;
      sign = s;
    }
    t_far = std::min(t_far, tb);
  }
  if (t_near > t_far) { return false; }
  Vec3 n{0.0, 0.0, 0.0};
  n[static_cast<std::size_t>(axis)] = sign;
  return take(t_near, n, t_min, best);
}

}  // namespace

bool intersect(const Primitive& p, const Vec3& o, const Vec3& d, double t_min, Hit& best) noexcept {
  switch (p.kind) {
    case PrimitiveKind::FRUSTUM:
      return frustum(p, o, d, t_min, best);
    case PrimitiveKind::ELLIPSOID:
      return ellipsoid(p, o, d, t_min, best);
    case PrimitiveKind::BOX:
      return box(p, o, d, t_min, best);
  }
  return false;
}

bool intersect_capsule(const Vec3& a, const Vec3& b, double r, const Vec3& o, const Vec3& d,
                       double t_min, Hit& best) noexcept {
  const double len = std::sqrt(dot(d, d));
  if (!(len > 0.0) || !(r > 0.0)) { return false; }
  const Vec3 rd = (1.0 / len) * d;  // unit direction: distances below are in metres
  const Vec3 ba = b - a;
  const Vec3 oa = o - a;
  const double baba = dot(ba, ba);
  const double bard = dot(ba, rd);
  const double baoa = dot(ba, oa);
  const double rdoa = dot(rd, oa);
  const double oaoa = dot(oa, oa);
  double t = -1.0;
  Vec3 normal{};
  // The cylinder's side (not for a sphere, nor for a ray along the axis).
  const double qa = baba - bard * bard;
  if (baba > 0.0 && qa > 1e-12 * baba) {
    const double qb = baba * rdoa - baoa * bard;
    const double qc = baba * oaoa - baoa * baoa - r * r * baba;
    const double h = qb * qb - qa * qc;
    if (h < 0.0) { return false; }  // the infinite cylinder is missed, so are the caps
    const double ts = (-qb - std::sqrt(h)) / qa;
    const double y = baoa + ts * bard;
    if (y > 0.0 && y < baba) {
      t = ts;
      normal = (oa + ts * rd) - (y / baba) * ba;
    }
  }
  if (t < 0.0) {  // the end caps: the sphere at a or at b, whichever the side's hit lies beyond
    for (const Vec3* c : {&a, &b}) {
      const Vec3 oc = o - *c;
      const double hb = dot(rd, oc);
      const double h = hb * hb - (dot(oc, oc) - r * r);
      if (h <= 0.0) { continue; }
      const double tc = -hb - std::sqrt(h);
      if (tc > 0.0 && (t < 0.0 || tc < t)) {
        t = tc;
        normal = oc + tc * rd;
      }
    }
  }
  if (t < 0.0) { return false; }
  const double t_ray = t / len;  // back to the caller's ray parameter
  if (t_ray <= t_min || t_ray >= best.t) { return false; }
  best.t = t_ray;
  best.normal = normal;
  return true;
}

}  // namespace orthoflow::simulation
