// Drawing of a validated plot: axes with ticks and labels, series (lines, markers, error bars),
// legend.
#include <cairo.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>
#include <string>

#include "evaluation/detail/line_plot_frame.hpp"

namespace orthoflow::evaluation::detail {
namespace {

// Draws text with its anchor at (x, y): ax/ay = 0 left/top, 0.5 centre, 1 right/bottom of the ink
// box.
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
    const double v = k * a.step,
                 p = y_axis ? f.py(v) : f.px(v);  // k * step: no drift from summing steps
    cairo_set_source_rgb(cr, 0.88, 0.88, 0.88);
    cairo_move_to(cr, y_axis ? f.x0 : p, y_axis ? p : f.y0);
    cairo_line_to(cr, y_axis ? f.x1 : p, y_axis ? p : f.y1);
    cairo_stroke(cr);
    cairo_set_source_rgb(cr, 0.2, 0.2, 0.2);
    text_at(cr, num(k == 0.0 ? 0.0 : v), y_axis ? f.x0 - 6 : p, y_axis ? p : f.y1 + 6,
            y_axis ? 1.0 : 0.5, y_axis ? 0.5 : 0.0);
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
  static constexpr std::array<double, 2> DASH{
      7.0, 4.0};  // series beyond the palette repeat a colour, dashed
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
  [[nodiscard]] bool contains(double px, double py) const {
    return px >= x && px <= x + w && py >= y && py <= y + h;
  }
};

// The plot corner whose legend box covers the fewest samples of the polylines (every 4 px along
// each segment, at most 256 per segment); ties keep the first of top-left, top-right, bottom-left,
// bottom-right.
Box legend_box(const PlotSpec& spec, const Frame& f, double w, double h) {
  const std::array<Box, 4> corners{{{f.x0 + 8, f.y0 + 8, w, h},
                                    {f.x1 - 8 - w, f.y0 + 8, w, h},
                                    {f.x0 + 8, f.y1 - 8 - h, w, h},
                                    {f.x1 - 8 - w, f.y1 - 8 - h, w, h}}};
  std::array<std::size_t, 4> covered{};
  for (const Series& s : spec.series) {
    for (std::size_t i = 0; i < s.x.size(); ++i) {
      const std::size_t prev = i == 0 ? 0 : i - 1;
      const double x = f.px(s.x[i]), y = f.py(s.y[i]), dx = f.px(s.x[prev]) - x,
                   dy = f.py(s.y[prev]) - y;
      const double n = std::clamp(std::ceil(std::hypot(dx, dy) / 4.0), 1.0, 256.0);
      for (double k = 0; k < n; k += 1.0) {
        for (std::size_t c = 0; c < 4; ++c)
          covered[c] += corners[c].contains(x + k / n * dx, y + k / n * dy) ? 1 : 0;
      }
    }
  }
  return corners[static_cast<std::size_t>(std::min_element(covered.begin(), covered.end()) -
                                          covered.begin())];
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
    if (spec.series[i].markers)
      cairo_arc(cr, box.x + 8 + SWATCH / 2, y, MARKER_RADIUS, 0.0, 2 * std::numbers::pi);
    cairo_fill(cr);
    cairo_set_source_rgb(cr, 0.0, 0.0, 0.0);
    text_at(cr, spec.series[i].name, box.x + 14 + SWATCH, y, 0.0, 0.5);
    y += ROW;
  }
  cairo_set_dash(cr, nullptr, 0, 0.0);
}

}  // namespace

void draw_plot(cairo_t* cr, const PlotSpec& spec, const Frame& f) {
  cairo_set_source_rgb(cr, 1.0, 1.0, 1.0);
  cairo_paint(cr);
  cairo_select_font_face(cr, "sans", CAIRO_FONT_SLANT_NORMAL, CAIRO_FONT_WEIGHT_NORMAL);
  draw_axes(cr, spec, f);
  cairo_save(cr);
  const double m =
      MARKER_RADIUS + 1;  // whole markers on the frame's edges; data beyond a fixed y range is cut
  cairo_rectangle(cr, f.x0 - m, f.y0 - m, f.x1 - f.x0 + 2 * m, f.y1 - f.y0 + 2 * m);
  cairo_clip(cr);
  for (std::size_t i = 0; i < spec.series.size(); ++i) draw_series(cr, spec.series[i], i, f);
  cairo_restore(cr);
  draw_legend(cr, spec, f);
}

}  // namespace orthoflow::evaluation::detail
