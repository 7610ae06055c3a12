#include "ui/camera_view.hpp"

#include <cairo.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <memory>

#include "engine/object_list_payload.hpp"
#include "ui/png_encode.hpp"

namespace orthoflow::ui {

namespace {

// One axis of the fit: pixel = f * ray + c by least squares over the measured pixels.
struct AxisFit {
  double n = 0, s = 0, ss = 0, p = 0, sp = 0, pp = 0;
  void add(double ray, double pixel) noexcept {
    n += 1;
    s += ray;
    ss += ray * ray;
    p += pixel;
    sp += ray * pixel;
    pp += pixel * pixel;
  }
  // Slope and intercept; false when the rays do not spread.
  bool solve(double& f, double& c) const noexcept {
    const double d = n * ss - s * s;
    if (n < 2 || !(std::abs(d) > 1e-12 * n * n)) return false;
    f = (n * sp - s * p) / d;
    c = (p - f * s) / n;
    return std::isfinite(f) && std::isfinite(c) && f > 0;
  }
  // Sum of squared residuals of pixel = f * ray + c.
  [[nodiscard]] double residual(double f, double c) const noexcept {
    return pp - 2 * f * sp - 2 * c * p + f * f * ss + 2 * f * c * s + c * c * n;
  }
};

bool measured(float x, float y, float z) noexcept {
  return std::isfinite(x) && std::isfinite(y) && std::isfinite(z) && z > 0.0F;
}

// Near is warm, far is cool: the measured depth range of the image over a blue-to-yellow ramp.
std::uint32_t depth_colour(float z, float z0, float z1) noexcept {
  const float t = z1 > z0 ? std::clamp((z - z0) / (z1 - z0), 0.0F, 1.0F) : 0.5F;
  const auto r = static_cast<std::uint32_t>(255.0F * (1.0F - t));
  const auto g = static_cast<std::uint32_t>(200.0F * (1.0F - 0.5F * t));
  const auto b = static_cast<std::uint32_t>(80.0F + 175.0F * t);
  return (r << 16) | (g << 8) | b;
}

struct SurfaceFree {
  void operator()(cairo_surface_t* s) const noexcept { cairo_surface_destroy(s); }
};
struct ContextFree {
  void operator()(cairo_t* c) const noexcept { cairo_destroy(c); }
};

bool shown(const ObjectView& o) noexcept {
  return o.track_id != 0 && (o.flags & engine::OBJECT_FRAGMENT) == 0;
}

}  // namespace

void prepare_camera_fonts() noexcept {
  cairo_surface_t* surface = cairo_image_surface_create(CAIRO_FORMAT_RGB24, 1, 1);
  cairo_t* g = cairo_create(surface);
  cairo_select_font_face(g, "sans-serif", CAIRO_FONT_SLANT_NORMAL, CAIRO_FONT_WEIGHT_BOLD);
  cairo_set_font_size(g, 11.0);
  cairo_text_extents_t extents;
  cairo_text_extents(g, "#0 Unknown", &extents);
  cairo_destroy(g);
  cairo_surface_destroy(surface);
}

PinholeFit fit_pinhole(const graphs::CameraImage& image) noexcept {
  PinholeFit fit;
  const std::size_t n = static_cast<std::size_t>(image.width) * image.height;
  if (image.x.size() < n || image.y.size() < n || image.z.size() < n) return fit;
  AxisFit u, v;
  for (std::uint32_t j = 0; j < image.height; ++j) {
    for (std::uint32_t i = 0; i < image.width; ++i) {
      const std::size_t k = static_cast<std::size_t>(j) * image.width + i;
      if (!measured(image.x[k], image.y[k], image.z[k])) continue;
      u.add(image.x[k] / image.z[k], i);
      v.add(image.y[k] / image.z[k], j);
    }
  }
  if (u.n < 64 || !u.solve(fit.fx, fit.cx) || !v.solve(fit.fy, fit.cy)) return fit;
  fit.rms_px = std::sqrt(std::max(0.0, u.residual(fit.fx, fit.cx) + v.residual(fit.fy, fit.cy)) /
                         (2.0 * u.n));
  fit.ok = fit.rms_px < 0.5;
  return fit;
}

std::vector<ImageBox> project_boxes(const PinholeFit& fit, std::uint32_t width,
                                    std::uint32_t height, const std::vector<ObjectView>& objects) {
  std::vector<ImageBox> boxes;
  if (!fit.ok) return boxes;
  for (const ObjectView& o : objects) {
    if (!shown(o)) continue;
    float u0 = std::numeric_limits<float>::max(), v0 = u0, u1 = -u0, v1 = -u0;
    bool in_front = true;
    for (int corner = 0; corner < 8; ++corner) {
      const float x = (corner & 1) != 0 ? o.bbox_max[0] : o.bbox_min[0];
      const float y = (corner & 2) != 0 ? o.bbox_max[1] : o.bbox_min[1];
      const float z = (corner & 4) != 0 ? o.bbox_max[2] : o.bbox_min[2];
      if (!(std::isfinite(x) && std::isfinite(y) && z > 0.01F)) {
        in_front = false;
        break;
      }
      const auto u = static_cast<float>(fit.fx * x / z + fit.cx);
      const auto v = static_cast<float>(fit.fy * y / z + fit.cy);
      u0 = std::min(u0, u);
      u1 = std::max(u1, u);
      v0 = std::min(v0, v);
      v1 = std::max(v1, v);
    }
    const auto w = static_cast<float>(width), h = static_cast<float>(height);
    if (!in_front || u1 < 0 || v1 < 0 || u0 > w || v0 > h) continue;
    boxes.push_back(
        {o.track_id, std::max(u0, 0.0F), std::max(v0, 0.0F), std::min(u1, w), std::min(v1, h)});
  }
  return boxes;
}

std::string render_camera_png(const graphs::CameraImage& image,
                              const std::vector<ObjectView>& objects) {
  const std::size_t n = static_cast<std::size_t>(image.width) * image.height;
  if (n == 0 || image.z.size() < n) return {};
  std::unique_ptr<cairo_surface_t, SurfaceFree> surface(cairo_image_surface_create(
      CAIRO_FORMAT_RGB24, static_cast<int>(image.width), static_cast<int>(image.height)));
  if (cairo_surface_status(surface.get()) != CAIRO_STATUS_SUCCESS) return {};
  cairo_surface_flush(surface.get());
  unsigned char* pixels = cairo_image_surface_get_data(surface.get());
  const int stride = cairo_image_surface_get_stride(surface.get());
  const bool colour = image.rgb.size() >= n;
  float z0 = std::numeric_limits<float>::max(), z1 = 0.0F;
  for (std::size_t k = 0; k < n && !colour; ++k) {
    if (!measured(image.x[k], image.y[k], image.z[k])) continue;
    z0 = std::min(z0, image.z[k]);
    z1 = std::max(z1, image.z[k]);
  }
  for (std::uint32_t j = 0; j < image.height; ++j) {
    auto* row = reinterpret_cast<std::uint32_t*>(pixels + static_cast<std::ptrdiff_t>(j) * stride);
    for (std::uint32_t i = 0; i < image.width; ++i) {
      const std::size_t k = static_cast<std::size_t>(j) * image.width + i;
      // RGB24 is 0x00RRGGBB in a native 32-bit word: the frame's colour as it is.
      row[i] = colour                                         ? image.rgb[k] & 0x00FFFFFFU
               : measured(image.x[k], image.y[k], image.z[k]) ? depth_colour(image.z[k], z0, z1)
                                                              : 0x202020U;
    }
  }
  cairo_surface_mark_dirty(surface.get());

  std::unique_ptr<cairo_t, ContextFree> g(cairo_create(surface.get()));
  cairo_select_font_face(g.get(), "sans-serif", CAIRO_FONT_SLANT_NORMAL, CAIRO_FONT_WEIGHT_BOLD);
  cairo_set_font_size(g.get(), 11.0);
  const std::vector<ImageBox> boxes =
      project_boxes(fit_pinhole(image), image.width, image.height, objects);
  for (const ImageBox& box : boxes) {
    const auto it = std::find_if(objects.begin(), objects.end(),
                                 [&](const ObjectView& o) { return o.track_id == box.track; });
    const bool known = it != objects.end() && !it->unknown;
    cairo_set_line_width(g.get(), 2.0);
    if (known)
      cairo_set_source_rgb(g.get(), 0.30, 0.69, 0.31);
    else
      cairo_set_source_rgb(g.get(), 0.85, 0.88, 0.90);
    cairo_rectangle(g.get(), box.u0, box.v0, box.u1 - box.u0, box.v1 - box.v0);
    cairo_stroke(g.get());
    char text[96];
    if (known)
      std::snprintf(text, sizeof text, "#%llu %s %.2f", static_cast<unsigned long long>(box.track),
                    it->label.c_str(), static_cast<double>(it->score));
    else
      std::snprintf(text, sizeof text, "#%llu Unknown", static_cast<unsigned long long>(box.track));
    cairo_text_extents_t extents;
    cairo_text_extents(g.get(), text, &extents);
    const double tx = std::min<double>(box.u0, image.width - extents.x_advance - 2);
    const double ty = box.v0 > 14 ? box.v0 - 3 : box.v0 + 13;
    cairo_set_source_rgba(g.get(), 0, 0, 0, 0.6);
    cairo_rectangle(g.get(), tx - 1, ty - 11, extents.x_advance + 3, 14);
    cairo_fill(g.get());
    cairo_set_source_rgb(g.get(), 1, 1, 1);
    cairo_move_to(g.get(), tx, ty);
    cairo_show_text(g.get(), text);
  }
  g.reset();
  cairo_surface_flush(surface.get());
  return encode_rgb24_png(cairo_image_surface_get_data(surface.get()),
                          cairo_image_surface_get_stride(surface.get()), image.width, image.height);
}

}  // namespace orthoflow::ui
