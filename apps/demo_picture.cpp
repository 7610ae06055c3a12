#include "apps/demo_picture.hpp"

#include <cairo.h>

#include <cstdio>
#include <memory>

#include "simulation/world/object_catalog.hpp"

namespace orthoflow::apps {

namespace {

constexpr int W = 640, H = 480;
constexpr double SCALE = 480.0;  // pixels per metre
// Base frame (x, y) -> pixels: the table (x -0.6..0.6, y -0.7..0.15) fills the picture, the
// camera's side at the bottom.
double px(double x) { return W / 2.0 + x * SCALE; }
double py(double y) { return 60.0 - y * SCALE; }

Eigen::Vector3d base(const Eigen::Isometry3d& base_from_camera, const simulation::Vec3& p) {
  return base_from_camera * Eigen::Vector3d(p[0], p[1], p[2]);
}

}  // namespace

Result<void, std::string> write_demo_picture(const graphs::TaskFrameView& view,
                                             const DemoMarks& marks, const std::string& path) {
  std::unique_ptr<cairo_surface_t, decltype(&cairo_surface_destroy)> surface(
      cairo_image_surface_create(CAIRO_FORMAT_RGB24, W, H), cairo_surface_destroy);
  std::unique_ptr<cairo_t, decltype(&cairo_destroy)> cr(cairo_create(surface.get()), cairo_destroy);
  cairo_t* c = cr.get();
  cairo_set_source_rgb(c, 0.2, 0.2, 0.22);
  cairo_paint(c);
  const Eigen::Isometry3d& x = *view.base_from_camera;
  const auto corners = simulation::table_corners(view.scene->table);
  cairo_set_source_rgb(c, 0.78, 0.70, 0.56);
  for (std::size_t k = 0; k < corners.size(); ++k) {
    const Eigen::Vector3d p = base(x, corners[k]);
    k == 0 ? cairo_move_to(c, px(p.x()), py(p.y())) : cairo_line_to(c, px(p.x()), py(p.y()));
  }
  cairo_close_path(c);
  cairo_fill(c);
  cairo_set_line_width(c, 2.0);
  if (marks.area != nullptr) {
    cairo_set_source_rgb(c, 0.2, 0.55, 0.2);
    const auto& a = *marks.area;
    cairo_rectangle(c, px(a.min.x()), py(a.max.y()), (a.max.x() - a.min.x()) * SCALE,
                    (a.max.y() - a.min.y()) * SCALE);
    cairo_stroke(c);
  }
  if (marks.user_place != nullptr) {
    cairo_set_source_rgb(c, 0.2, 0.55, 0.2);
    cairo_new_path(c);
    cairo_arc(c, px(marks.user_place->x()), py(marks.user_place->y()), 0.06 * SCALE, 0, 6.2832);
    cairo_stroke(c);
  }
  const simulation::TableFrame t = simulation::table_frame(view.scene->table);
  cairo_select_font_face(c, "sans-serif", CAIRO_FONT_SLANT_NORMAL, CAIRO_FONT_WEIGHT_NORMAL);
  cairo_set_font_size(c, 12.0);
  for (const simulation::PlacedObject& o : view.scene->objects) {
    const Eigen::Vector3d p = base(x, t.point(o.table_x, o.table_y));
    const std::uint32_t rgb = o.model.rgb;
    cairo_set_source_rgb(c, ((rgb >> 16) & 0xFF) / 255.0, ((rgb >> 8) & 0xFF) / 255.0,
                         (rgb & 0xFF) / 255.0);
    cairo_new_path(c);  // no line from the previous label
    cairo_arc(c, px(p.x()), py(p.y()), o.model.footprint_radius * SCALE, 0, 6.2832);
    static_cast<int>(o.id) == view.held_object_id ? cairo_fill(c) : cairo_stroke(c);
    cairo_set_source_rgb(c, 0.05, 0.05, 0.05);
    cairo_move_to(c, px(p.x()) - 14, py(p.y()) + 4);
    cairo_show_text(c, simulation::category_name(o.model.category));
  }
  cairo_set_source_rgba(c, 0.15, 0.35, 0.85, 0.8);
  cairo_set_line_cap(c, CAIRO_LINE_CAP_ROUND);
  for (const simulation::BodyCapsule& b : view.scene->robot) {
    const Eigen::Vector3d a = base(x, b.a), e = base(x, b.b);
    cairo_new_path(c);
    cairo_set_line_width(c, 2.0 * b.radius * SCALE);
    cairo_move_to(c, px(a.x()), py(a.y()));
    cairo_line_to(c, px(e.x()), py(e.y()));
    cairo_stroke(c);
  }
  char text[96];
  std::snprintf(text, sizeof text, "t %.1f s  frame %llu  %s", view.seconds,
                static_cast<unsigned long long>(view.frame), view.phase);
  cairo_set_source_rgb(c, 0.95, 0.95, 0.95);
  cairo_set_font_size(c, 16.0);
  cairo_move_to(c, 12, H - 12);
  cairo_show_text(c, text);
  cairo_surface_flush(surface.get());
  if (cairo_surface_write_to_png(surface.get(), path.c_str()) != CAIRO_STATUS_SUCCESS)
    return err(path + ": cannot write the PNG");
  return {};
}

}  // namespace orthoflow::apps
