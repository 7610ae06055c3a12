#pragma once
/// @file
/// @brief Internal to line_plot.cpp / line_plot_draw.cpp: the plot layout (palette, margins,
/// data-to-device frame) shared by validation (which builds the frame) and drawing.
#include <cairo.h>

#include <array>
#include <cmath>
#include <cstdio>
#include <memory>
#include <string>

#include "evaluation/line_plot.hpp"

namespace orthoflow::evaluation::detail {

struct Rgb {
  double r, g, b;  // 0..255
};
// Okabe & Ito (2008) colour-blind-safe palette, most distinct first; yellow last but one (weak on
// white).
constexpr std::array<Rgb, 8> PALETTE{{{0, 114, 178},
                                      {213, 94, 0},
                                      {0, 158, 115},
                                      {230, 159, 0},
                                      {204, 121, 167},
                                      {86, 180, 233},
                                      {240, 228, 66},
                                      {0, 0, 0}}};
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

/// @brief Short decimal text of @p v ("%g").
inline std::string num(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%g", v);
  return buf;
}

/// @brief Draws the whole plot @p spec on @p cr inside frame @p f (background, axes, series,
/// legend).
void draw_plot(cairo_t* cr, const PlotSpec& spec, const Frame& f);

}  // namespace orthoflow::evaluation::detail
