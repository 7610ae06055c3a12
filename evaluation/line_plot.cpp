#include "evaluation/line_plot.hpp"

#include <cairo-svg.h>
#include <cairo.h>

#include <algorithm>
#include <array>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <memory>
#include <numbers>
#include <optional>

namespace orthoflow::evaluation {

namespace {

struct Rgb {
  double r, g, b;  // 0..255
};
// Okabe & Ito (2008) colour-blind-safe palette, most distinct first; yellow last but one (weak on white).
constexpr std::array<Rgb, 8> PALETTE{{{0, 114, 178}, {213, 94, 0}, {0, 158, 115}, {230, 159, 0},
                                      {204, 121, 167}, {86, 180, 233}, {240, 228, 66}, {0, 0, 0}}};
constexpr double LEFT = 78, RIGHT = 30, BOTTOM = 56, TOP_NO_TITLE = 20, TOP_TITLE = 42;
constexpr double MARKER_RADIUS = 3.5, LINE_WIDTH = 2.0;
constexpr double MAX_TICKS = 40;  // guards the tick loops against degenerate (tiny relative) ranges

using SurfacePtr = std::unique_ptr<cairo_surface_t, decltype(&cairo_surface_destroy)>;
using ContextPtr = std::unique_ptr<cairo_t, decltype(&cairo_destroy)>;

struct Range {
  double lo = INFINITY, hi = -INFINITY;
  void grow(double v) { lo = std::min(lo, v), hi = std::max(hi, v); }
};

// An axis from lo to hi with ticks at integer multiples of step (1, 2 or 5 x 10^k).
struct Axis {
  double lo = 0, hi = 1, step = 0.2;
};

// Maps data to device coordinates inside the plot rectangle [x0, x1] x [y0, y1] (y0 at the top).
struct Frame {
  double x0 = 0, x1 = 0, y0 = 0, y1 = 0;
  Axis xa, ya;
  [[nodiscard]] double px(double x) const { return x0 + (x - xa.lo) / (xa.hi - xa.lo) * (x1 - x0); }
  [[nodiscard]] double py(double y) const { return y1 - (y - ya.lo) / (ya.hi - ya.lo) * (y1 - y0); }
};

Unexpected<PlotError> fail(PlotError::Code code, std::string message) {
  return err(PlotError{code, std::move(message)});
}

std::string num(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%g", v);
  return buf;
}

Result<void, PlotError> check_series(const Series& s, std::size_t index) {
  const auto bad = [&](const std::string& what) {
    return fail(PlotError::Code::BAD_SERIES, "series '" + s.name + "' (#" + std::to_string(index) + ")" + what);
  };
  if (s.x.size() != s.y.size()) {
    return bad(": " + std::to_string(s.x.size()) + " x values but " + std::to_string(s.y.size()) + " y values");
  }
  if (!s.y_err.empty() && s.y_err.size() != s.y.size()) {
    return bad(": " + std::to_string(s.y_err.size()) + " y_err values for " + std::to_string(s.y.size()) + " points");
  }
  for (std::size_t i = 0; i < s.x.size(); ++i) {
    if (!std::isfinite(s.x[i])) return bad(": x[" + std::to_string(i) + "] is " + num(s.x[i]));
    if (!std::isfinite(s.y[i])) return bad(": y[" + std::to_string(i) + "] is " + num(s.y[i]));
    if (!s.y_err.empty() && !(std::isfinite(s.y_err[i]) && s.y_err[i] >= 0)) {
      return bad(": y_err[" + std::to_string(i) + "] is " + num(s.y_err[i]) + " (want finite, >= 0)");
    }
  }
  return {};
}

// Widens a range too narrow to draw (one point, all-equal values) symmetrically around its value.
Range padded(Range r) {
  const double mag = std::max(std::abs(r.lo), std::abs(r.hi));
  if (r.hi - r.lo > 1e-9 * mag && r.hi - r.lo > 1e-200) return r;
  const double pad = mag > 1e-200 ? 0.1 * mag : 1.0;
  return {r.lo - pad, r.hi + pad};
}

// Heckbert, "Nice numbers for graph labels" (Graphics Gems, 1990): the step rounded to 1, 2 or 5 x 10^k.
double nice_step(double span, double target_ticks) {
  const double raw = span / target_ticks;
  const double mag = std::pow(10.0, std::floor(std::log10(raw)));
  const double f = raw / mag;
  return (f <= 1.0 ? 1.0 : f <= 2.0 ? 2.0 : f <= 5.0 ? 5.0 : 10.0) * mag;
}

// Free ends snap outwards to a tick; fixed ends (spec.y_min / y_max) stay where they are. Empty if the range
// overflows or is too narrow for its magnitude to tick.
std::optional<Axis> make_axis(Range r, double target_ticks, bool fixed_lo, bool fixed_hi) {
  Axis a{r.lo, r.hi, nice_step(r.hi - r.lo, target_ticks)};
  if (!fixed_lo) a.lo = std::floor(r.lo / a.step) * a.step;
  if (!fixed_hi) a.hi = std::ceil(r.hi / a.step) * a.step;
  // Tick indices k = value / step must stay exact integers in a double (< 2^53) for the tick loop.
  const bool ok = std::isfinite(a.lo) && std::isfinite(a.hi) && a.step > 0 && a.hi > a.lo &&
                  std::max(std::abs(a.lo), std::abs(a.hi)) / a.step < 1e15;
  if (!ok || !((a.hi - a.lo) / a.step <= MAX_TICKS)) return std::nullopt;
  return a;
}

Result<Frame, PlotError> make_frame(const PlotSpec& spec) {
  Range xr, yr;
  for (const Series& s : spec.series) {
    for (std::size_t i = 0; i < s.x.size(); ++i) {
      const double e = s.y_err.empty() ? 0.0 : s.y_err[i];
      xr.grow(s.x[i]), yr.grow(s.y[i] - e), yr.grow(s.y[i] + e);
    }
  }
  if (spec.y_min) yr.lo = *spec.y_min;
  if (spec.y_max) yr.hi = *spec.y_max;
  if (!(yr.hi > yr.lo)) yr = spec.y_min ? Range{yr.lo, yr.lo} : Range{yr.hi, yr.hi};  // all data beyond a fixed end
  yr = padded(yr);
  if (spec.y_min) yr.lo = *spec.y_min;
  if (spec.y_max) yr.hi = *spec.y_max;
  Frame f{LEFT, spec.width - RIGHT, spec.title.empty() ? TOP_NO_TITLE : TOP_TITLE, spec.height - BOTTOM, {}, {}};
  const auto maybe_x = make_axis(padded(xr), std::clamp((f.x1 - f.x0) / 90.0, 3.0, 10.0), false, false);
  const auto maybe_y = make_axis(yr, std::clamp((f.y1 - f.y0) / 60.0, 3.0, 10.0), !!spec.y_min, !!spec.y_max);
  if (!maybe_x || !maybe_y) {
    const Range& r = maybe_x ? yr : xr;  // a fixed y range at fault is the spec's, else the data's
    return fail(maybe_x && spec.y_min && spec.y_max ? PlotError::Code::BAD_SPEC : PlotError::Code::BAD_SERIES,
                std::string(maybe_x ? "y" : "x") + " range [" + num(r.lo) + ", " + num(r.hi) +
                    "] cannot be drawn (overflow or too narrow)");
  }
  f.xa = *maybe_x, f.ya = *maybe_y;
  return f;
}

// Draws text with its anchor at (x, y): ax/ay = 0 left/top, 0.5 centre, 1 right/bottom of the ink box.
void text_at(cairo_t* cr, const std::string& text, double x, double y, double ax, double ay) {
  cairo_text_extents_t ext;
  cairo_text_extents(cr, text.c_str(), &ext);
  cairo_move_to(cr, x - ext.x_bearing - ax * ext.width, y - ext.y_bearing - ay * ext.height);
  cairo_show_text(cr, text.c_str());
}

// Grid lines and tick labels of one axis (the y axis when y_axis is true).
void draw_ticks(cairo_t* cr, const Frame& f, bool y_axis) {
  const Axis& a = y_axis ? f.ya : f.xa;
  const double first = std::ceil(a.lo / a.step - 1e-9), last = std::floor(a.hi / a.step + 1e-9);
  cairo_set_font_size(cr, 11.0);
  for (double k = first; k <= last; k += 1.0) {  // make_axis bounds the count and keeps k exact
    const double v = k * a.step, p = y_axis ? f.py(v) : f.px(v);  // k * step: no drift from summing steps
    cairo_set_source_rgb(cr, 0.88, 0.88, 0.88);
    cairo_move_to(cr, y_axis ? f.x0 : p, y_axis ? p : f.y0);
    cairo_line_to(cr, y_axis ? f.x1 : p, y_axis ? p : f.y1);
    cairo_stroke(cr);
    cairo_set_source_rgb(cr, 0.2, 0.2, 0.2);
    text_at(cr, num(k == 0.0 ? 0.0 : v), y_axis ? f.x0 - 6 : p, y_axis ? p : f.y1 + 6, y_axis ? 1.0 : 0.5,
            y_axis ? 0.5 : 0.0);
  }
}

void draw_axes(cairo_t* cr, const PlotSpec& spec, const Frame& f) {
  cairo_set_line_width(cr, 1.0);
  draw_ticks(cr, f, false);
  draw_ticks(cr, f, true);
  cairo_set_source_rgb(cr, 0.0, 0.0, 0.0);
  cairo_rectangle(cr, f.x0, f.y0, f.x1 - f.x0, f.y1 - f.y0);
  cairo_stroke(cr);
  cairo_set_font_size(cr, 13.0);
  text_at(cr, spec.x_label, (f.x0 + f.x1) / 2, spec.height - 8.0, 0.5, 1.0);
  cairo_save(cr);
  cairo_translate(cr, 8.0, (f.y0 + f.y1) / 2);
  cairo_rotate(cr, -std::numbers::pi / 2);
  text_at(cr, spec.y_label, 0.0, 0.0, 0.5, 0.0);
  cairo_restore(cr);
  cairo_select_font_face(cr, "sans", CAIRO_FONT_SLANT_NORMAL, CAIRO_FONT_WEIGHT_BOLD);
  cairo_set_font_size(cr, 16.0);
  text_at(cr, spec.title, spec.width / 2.0, 10.0, 0.5, 0.0);
  cairo_select_font_face(cr, "sans", CAIRO_FONT_SLANT_NORMAL, CAIRO_FONT_WEIGHT_NORMAL);
}

void set_series_style(cairo_t* cr, std::size_t index) {
  const Rgb& c = PALETTE[index % PALETTE.size()];
  cairo_set_source_rgb(cr, c.r / 255.0, c.g / 255.0, c.b / 255.0);
  cairo_set_line_width(cr, LINE_WIDTH);
  static constexpr std::array<double, 2> DASH{7.0, 4.0};  // series beyond the palette repeat a colour, dashed
  cairo_set_dash(cr, DASH.data(), index < PALETTE.size() ? 0 : 2, 0.0);
}

void draw_series(cairo_t* cr, const Series& s, std::size_t index, const Frame& f) {
  set_series_style(cr, index);
  for (std::size_t i = 0; i < s.x.size(); ++i) cairo_line_to(cr, f.px(s.x[i]), f.py(s.y[i]));
  cairo_stroke(cr);
  cairo_set_dash(cr, nullptr, 0, 0.0);
  cairo_set_line_width(cr, 1.2);
  for (std::size_t i = 0; i < s.y_err.size(); ++i) {
    const double x = f.px(s.x[i]), lo = f.py(s.y[i] - s.y_err[i]), hi = f.py(s.y[i] + s.y_err[i]);
    cairo_move_to(cr, x, lo), cairo_line_to(cr, x, hi);
    cairo_move_to(cr, x - 3, lo), cairo_line_to(cr, x + 3, lo);
    cairo_move_to(cr, x - 3, hi), cairo_line_to(cr, x + 3, hi);
  }
  cairo_stroke(cr);
  if (!s.markers) return;
  for (std::size_t i = 0; i < s.x.size(); ++i) {
    cairo_new_sub_path(cr);
    cairo_arc(cr, f.px(s.x[i]), f.py(s.y[i]), MARKER_RADIUS, 0.0, 2 * std::numbers::pi);
  }
  cairo_fill(cr);
}

struct Box {  // a legend placement in device coordinates
  double x = 0, y = 0, w = 0, h = 0;
  [[nodiscard]] bool contains(double px, double py) const { return px >= x && px <= x + w && py >= y && py <= y + h; }
};

// The plot corner whose legend box covers the fewest samples of the polylines (every 4 px along each segment,
// at most 256 per segment); ties keep the first of top-left, top-right, bottom-left, bottom-right.
Box legend_box(const PlotSpec& spec, const Frame& f, double w, double h) {
  const std::array<Box, 4> corners{{{f.x0 + 8, f.y0 + 8, w, h}, {f.x1 - 8 - w, f.y0 + 8, w, h},
                                    {f.x0 + 8, f.y1 - 8 - h, w, h}, {f.x1 - 8 - w, f.y1 - 8 - h, w, h}}};
  std::array<std::size_t, 4> covered{};
  for (const Series& s : spec.series) {
    for (std::size_t i = 0; i < s.x.size(); ++i) {
      const std::size_t prev = i == 0 ? 0 : i - 1;
      const double x = f.px(s.x[i]), y = f.py(s.y[i]), dx = f.px(s.x[prev]) - x, dy = f.py(s.y[prev]) - y;
      const double n = std::clamp(std::ceil(std::hypot(dx, dy) / 4.0), 1.0, 256.0);
      for (double k = 0; k < n; k += 1.0) {
        for (std::size_t c = 0; c < 4; ++c) covered[c] += corners[c].contains(x + k / n * dx, y + k / n * dy) ? 1 : 0;
      }
    }
  }
  return corners[static_cast<std::size_t>(std::min_element(covered.begin(), covered.end()) - covered.begin())];
}

void draw_legend(cairo_t* cr, const PlotSpec& spec, const Frame& f) {
  constexpr double ROW = 18, SWATCH = 24;
  cairo_set_font_size(cr, 12.0);
  double text_w = 0, rows = 0;
  for (const Series& s : spec.series) {
    if (s.name.empty()) continue;
    cairo_text_extents_t ext;
    cairo_text_extents(cr, s.name.c_str(), &ext);
    text_w = std::max(text_w, ext.x_advance), rows += 1;
  }
  if (rows == 0) return;
  const Box box = legend_box(spec, f, text_w + SWATCH + 22, rows * ROW + 8);
  cairo_rectangle(cr, box.x, box.y, box.w, box.h);
  cairo_set_source_rgba(cr, 1.0, 1.0, 1.0, 0.9);
  cairo_fill_preserve(cr);
  cairo_set_source_rgb(cr, 0.6, 0.6, 0.6);
  cairo_set_line_width(cr, 1.0);
  cairo_stroke(cr);
  double y = box.y + 4 + ROW / 2;
  for (std::size_t i = 0; i < spec.series.size(); ++i) {
    if (spec.series[i].name.empty()) continue;
    set_series_style(cr, i);
    cairo_move_to(cr, box.x + 8, y), cairo_line_to(cr, box.x + 8 + SWATCH, y);
    cairo_stroke(cr);
    if (spec.series[i].markers) cairo_arc(cr, box.x + 8 + SWATCH / 2, y, MARKER_RADIUS, 0.0, 2 * std::numbers::pi);
    cairo_fill(cr);
    cairo_set_source_rgb(cr, 0.0, 0.0, 0.0);
    text_at(cr, spec.series[i].name, box.x + 14 + SWATCH, y, 0.0, 0.5);
    y += ROW;
  }
  cairo_set_dash(cr, nullptr, 0, 0.0);
}

void draw_plot(cairo_t* cr, const PlotSpec& spec, const Frame& f) {
  cairo_set_source_rgb(cr, 1.0, 1.0, 1.0);
  cairo_paint(cr);
  cairo_select_font_face(cr, "sans", CAIRO_FONT_SLANT_NORMAL, CAIRO_FONT_WEIGHT_NORMAL);
  draw_axes(cr, spec, f);
  cairo_save(cr);
  const double m = MARKER_RADIUS + 1;  // whole markers on the frame's edges; data beyond a fixed y range is cut
  cairo_rectangle(cr, f.x0 - m, f.y0 - m, f.x1 - f.x0 + 2 * m, f.y1 - f.y0 + 2 * m);
  cairo_clip(cr);
  for (std::size_t i = 0; i < spec.series.size(); ++i) draw_series(cr, spec.series[i], i, f);
  cairo_restore(cr);
  draw_legend(cr, spec, f);
}

Unexpected<PlotError> write_failed(const std::filesystem::path& path, const char* why) {
  return fail(PlotError::Code::WRITE_FAILED, "cannot write '" + path.string() + "': " + why);
}

Result<void, PlotError> cairo_checked(cairo_status_t status, const std::filesystem::path& path) {
  if (status == CAIRO_STATUS_SUCCESS) return {};
  return write_failed(path, cairo_status_to_string(status));
}

// Draws on @p surface and reports cairo's verdict (an error status sticks to the surface or the context).
Result<void, PlotError> render(cairo_surface_t* surface, const PlotSpec& spec, const std::filesystem::path& path) {
  if (auto r = cairo_checked(cairo_surface_status(surface), path); !r) return r;
  const ContextPtr cr(cairo_create(surface), cairo_destroy);
  draw_plot(cr.get(), spec, *make_frame(spec));  // validate_plot ran first: the frame exists
  cairo_surface_flush(surface);
  return cairo_checked(cairo_status(cr.get()), path);
}

cairo_status_t append_to_string(void* closure, const unsigned char* data, unsigned int length) {
  static_cast<std::string*>(closure)->append(reinterpret_cast<const char*>(data), length);
  return CAIRO_STATUS_SUCCESS;
}

// cairo names the top-level group after a process-wide surface counter ("surface83"); a fixed name makes the
// bytes depend on the spec only. Nothing else in our output references that id.
void fix_surface_id(std::string& svg) {
  const std::string key = "<g id=\"surface";
  const std::size_t at = svg.find(key);
  if (at == std::string::npos) return;
  const std::size_t digits = at + key.size(), end = svg.find('"', digits);
  if (end != std::string::npos) svg.replace(digits, end - digits, "1");
}

}  // namespace

const char* to_string(PlotError::Code code) noexcept {
  switch (code) {
    case PlotError::Code::EMPTY: return "empty";
    case PlotError::Code::BAD_SERIES: return "bad_series";
    case PlotError::Code::BAD_SPEC: return "bad_spec";
    case PlotError::Code::WRITE_FAILED: return "write_failed";
  }
  return "unknown";
}

std::string PlotError::to_string() const { return std::string(evaluation::to_string(code)) + ": " + message; }

Result<void, PlotError> validate_plot(const PlotSpec& spec) {
  const auto side_ok = [](int v) { return v >= MIN_PLOT_SIDE && v <= MAX_PLOT_SIDE; };
  if (!side_ok(spec.width) || !side_ok(spec.height)) {
    const std::string limits = "[" + std::to_string(MIN_PLOT_SIDE) + ", " + std::to_string(MAX_PLOT_SIDE) + "]";
    return fail(PlotError::Code::BAD_SPEC, "plot '" + spec.title + "': size " + std::to_string(spec.width) + "x" +
                                               std::to_string(spec.height) + " outside " + limits);
  }
  const bool lo_ok = !spec.y_min || std::isfinite(*spec.y_min), hi_ok = !spec.y_max || std::isfinite(*spec.y_max);
  if (!lo_ok || !hi_ok || (spec.y_min && spec.y_max && !(*spec.y_min < *spec.y_max))) {
    return fail(PlotError::Code::BAD_SPEC, "plot '" + spec.title + "': fixed y range not finite or not y_min < y_max");
  }
  bool any_point = false;
  for (std::size_t i = 0; i < spec.series.size(); ++i) {
    if (auto r = check_series(spec.series[i], i); !r) return r;
    any_point = any_point || !spec.series[i].x.empty();
  }
  if (!any_point) return fail(PlotError::Code::EMPTY, "plot '" + spec.title + "': no series with a point to draw");
  if (auto frame_result = make_frame(spec); !frame_result) return err(frame_result.error());
  return {};
}

Result<void, PlotError> write_plot_png(const PlotSpec& spec, const std::filesystem::path& path) {
  if (auto r = validate_plot(spec); !r) return r;
  const SurfacePtr surface(cairo_image_surface_create(CAIRO_FORMAT_ARGB32, spec.width, spec.height),
                           cairo_surface_destroy);
  if (auto r = render(surface.get(), spec, path); !r) return r;
  return cairo_checked(cairo_surface_write_to_png(surface.get(), path.c_str()), path);
}

Result<void, PlotError> write_plot_svg(const PlotSpec& spec, const std::filesystem::path& path) {
  if (auto r = validate_plot(spec); !r) return r;
  std::string svg;  // rendered in memory first: the file is written whole, or not at all on a cairo error
  {
    const SurfacePtr surface(cairo_svg_surface_create_for_stream(append_to_string, &svg, spec.width, spec.height),
                             cairo_surface_destroy);
    if (auto r = render(surface.get(), spec, path); !r) return r;
    cairo_surface_finish(surface.get());
    if (auto r = cairo_checked(cairo_surface_status(surface.get()), path); !r) return r;
  }
  fix_surface_id(svg);
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out.write(svg.data(), static_cast<std::streamsize>(svg.size()));
  out.close();
  if (!out) return write_failed(path, std::strerror(errno));
  return {};
}

}  // namespace orthoflow::evaluation
