#include "apps/scene_snapshot_png.hpp"

#include <cairo.h>

#include <algorithm>
#include <array>
#include <cstdio>
#include <memory>

#include "kernels/convex_hull.hpp"

namespace orthoflow::apps {

namespace {

constexpr int SIZE = 800;
constexpr double MARGIN = 40.0;
constexpr double AXIS_M = 0.06;  // drawn length of a GOOD frame axis

using Vec3 = std::array<double, 3>;
double dot(const Vec3& a, const Vec3& b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }

// Maps table-plane (u, v) in metres to pixels, fitting the table polygon (or the objects) in the
// picture.
struct View {
  double u0 = 0, v0 = 0, scale = 1;
  [[nodiscard]] double px(double u) const { return MARGIN + (u - u0) * scale; }
  [[nodiscard]] double py(double v) const { return SIZE - MARGIN - (v - v0) * scale; }
};

View fit(const graphs::SceneSnapshot& s, const kernels::PlaneBasis& b) {
  double lo_u = 1e9, hi_u = -1e9, lo_v = 1e9, hi_v = -1e9;
  auto grow = [&](double u, double v) {
    lo_u = std::min(lo_u, u), hi_u = std::max(hi_u, u), lo_v = std::min(lo_v, v),
    hi_v = std::max(hi_v, v);
  };
  for (std::size_t k = 0; k < s.hull_u.size(); ++k) grow(s.hull_u[k], s.hull_v[k]);
  for (const auto& o : s.objects) {
    const Vec3 c{o.stats.centroid[0] - b.origin[0], o.stats.centroid[1] - b.origin[1],
                 o.stats.centroid[2] - b.origin[2]};
    grow(dot(c, b.u), dot(c, b.v));
  }
  View view;
  view.u0 = lo_u;
  view.v0 = lo_v;
  view.scale = (SIZE - 2 * MARGIN) / std::max({hi_u - lo_u, hi_v - lo_v, 1e-3});
  return view;
}

void draw_object(cairo_t* cr, const graphs::ObjectRecord& o, const kernels::PlaneBasis& b,
                 const View& view) {
  const Vec3 c{o.stats.centroid[0] - b.origin[0], o.stats.centroid[1] - b.origin[1],
               o.stats.centroid[2] - b.origin[2]};
  const double cu = dot(c, b.u), cv = dot(c, b.v);
  if (o.described) {
    for (int axis = 0; axis < 2;
         ++axis) {  // rows 0 and 1 of the world->object rotation are X and Y
      const auto a = static_cast<std::size_t>(axis) * 4;
      const Vec3 dir{o.frame[a], o.frame[a + 1], o.frame[a + 2]};
      cairo_set_source_rgb(cr, axis == 0 ? 0.85 : 0.1, axis == 0 ? 0.1 : 0.65, 0.1);
      cairo_move_to(cr, view.px(cu), view.py(cv));
      cairo_line_to(cr, view.px(cu + AXIS_M * dot(dir, b.u)), view.py(cv + AXIS_M * dot(dir, b.v)));
      cairo_stroke(cr);
    }
  }
  char text[160];
  std::snprintf(text, sizeof text, "#%u %s", o.track_id,
                o.unknown ? "unknown" : std::string(o.label.view()).c_str());
  cairo_set_source_rgb(cr, 0.0, 0.0, 0.0);
  cairo_move_to(cr, view.px(cu) + 6, view.py(cv) - 6);
  cairo_show_text(cr, text);
}

}  // namespace

Result<void, std::string> write_scene_snapshot_png(const graphs::SceneSnapshot& s,
                                                   const std::string& path) {
  if (!s.valid) return err(std::string("snapshot: no frame with objects to draw"));
  const kernels::PlaneBasis b = kernels::make_plane_basis(s.plane);
  const View view = fit(s, b);
  std::unique_ptr<cairo_surface_t, decltype(&cairo_surface_destroy)> surface(
      cairo_image_surface_create(CAIRO_FORMAT_RGB24, SIZE, SIZE), cairo_surface_destroy);
  std::unique_ptr<cairo_t, decltype(&cairo_destroy)> owner(cairo_create(surface.get()),
                                                           cairo_destroy);
  cairo_t* cr = owner.get();
  cairo_set_source_rgb(cr, 1, 1, 1);
  cairo_paint(cr);
  cairo_set_source_rgb(cr, 0.85, 0.8, 0.7);  // the table
  for (std::size_t k = 0; k < s.hull_u.size(); ++k)
    cairo_line_to(cr, view.px(s.hull_u[k]), view.py(s.hull_v[k]));
  cairo_close_path(cr);
  cairo_fill(cr);
  cairo_set_source_rgb(cr, 0.3, 0.4, 0.8);  // object points
  for (std::size_t i = 0; i < s.x.size(); ++i) {
    const Vec3 p{s.x[i] - b.origin[0], s.y[i] - b.origin[1], s.z[i] - b.origin[2]};
    cairo_rectangle(cr, view.px(dot(p, b.u)) - 0.5, view.py(dot(p, b.v)) - 0.5, 1.0, 1.0);
  }
  cairo_fill(cr);
  cairo_set_line_width(cr, 2.0);
  cairo_set_font_size(cr, 13.0);
  for (const auto& o : s.objects) draw_object(cr, o, b, view);
  char title[96];
  std::snprintf(title, sizeof title, "frame %llu: %zu objects (view from above the table)",
                static_cast<unsigned long long>(s.frame_id), s.objects.size());
  cairo_move_to(cr, 10, 20);
  cairo_show_text(cr, title);
  if (cairo_surface_write_to_png(surface.get(), path.c_str()) != CAIRO_STATUS_SUCCESS) {
    return err("snapshot: cannot write '" + path + "'");
  }
  return {};
}

}  // namespace orthoflow::apps
