#include "evaluation/line_plot.hpp"

#include <cairo-svg.h>
#include <cairo.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <memory>
#include <numbers>
#include <optional>

#include "core/file_output.hpp"
#include "evaluation/detail/line_plot_frame.hpp"

namespace orthoflow::evaluation {

namespace {

using namespace detail;  // NOLINT: the shared plot layout of line_plot_frame.hpp

Unexpected<PlotError> fail(PlotError::Code code, std::string message) {
  return err(PlotError{code, std::move(message)});
}

Result<void, PlotError> check_series(const Series& s, std::size_t index) {
  const auto bad = [&](const std::string& what) {
    return fail(PlotError::Code::BAD_SERIES,
                "series '" + s.name + "' (#" + std::to_string(index) + ")" + what);
  };
  if (s.x.size() != s.y.size()) {
    return bad(": " + std::to_string(s.x.size()) + " x values but " + std::to_string(s.y.size()) +
               " y values");
  }
  if (!s.y_err.empty() && s.y_err.size() != s.y.size()) {
    return bad(": " + std::to_string(s.y_err.size()) + " y_err values for " +
               std::to_string(s.y.size()) + " points");
  }
  for (std::size_t i = 0; i < s.x.size(); ++i) {
    if (!std::isfinite(s.x[i])) return bad(": x[" + std::to_string(i) + "] is " + num(s.x[i]));
    if (!std::isfinite(s.y[i])) return bad(": y[" + std::to_string(i) + "] is " + num(s.y[i]));
    if (!s.y_err.empty() && !(std::isfinite(s.y_err[i]) && s.y_err[i] >= 0)) {
      return bad(": y_err[" + std::to_string(i) + "] is " + num(s.y_err[i]) +
                 " (want finite, >= 0)");
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

// Heckbert, "Nice numbers for graph labels" (Graphics Gems, 1990): the step rounded to 1, 2 or 5 x
// 10^k.
double nice_step(double span, double target_ticks) {
  const double raw = span / target_ticks;
  const double mag = std::pow(10.0, std::floor(std::log10(raw)));
  const double f = raw / mag;
  return (f <= 1.0 ? 1.0 : f <= 2.0 ? 2.0 : f <= 5.0 ? 5.0 : 10.0) * mag;
}

// Free ends snap outwards to a tick; fixed ends (spec.y_min / y_max) stay where they are. Empty if
// the range overflows or is too narrow for its magnitude to tick.
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
  if (!(yr.hi > yr.lo))
    yr = spec.y_min ? Range{yr.lo, yr.lo} : Range{yr.hi, yr.hi};  // all data beyond a fixed end
  yr = padded(yr);
  if (spec.y_min) yr.lo = *spec.y_min;
  if (spec.y_max) yr.hi = *spec.y_max;
  Frame f{LEFT,
          spec.width - RIGHT,
          spec.title.empty() ? TOP_NO_TITLE : TOP_TITLE,
          spec.height - BOTTOM,
          {},
          {}};
  const auto maybe_x =
      make_axis(padded(xr), std::clamp((f.x1 - f.x0) / 90.0, 3.0, 10.0), false, false);
  const auto maybe_y =
      make_axis(yr, std::clamp((f.y1 - f.y0) / 60.0, 3.0, 10.0), !!spec.y_min, !!spec.y_max);
  if (!maybe_x || !maybe_y) {
    const Range& r = maybe_x ? yr : xr;  // a fixed y range at fault is the spec's, else the data's
    return fail(maybe_x && spec.y_min && spec.y_max ? PlotError::Code::BAD_SPEC
                                                    : PlotError::Code::BAD_SERIES,
                std::string(maybe_x ? "y" : "x") + " range [" + num(r.lo) + ", " + num(r.hi) +
                    "] cannot be drawn (overflow or too narrow)");
  }
  f.xa = *maybe_x, f.ya = *maybe_y;
  return f;
}

Unexpected<PlotError> write_failed(const std::filesystem::path& path, const char* why) {
  return fail(PlotError::Code::WRITE_FAILED, "cannot write '" + path.string() + "': " + why);
}

Result<void, PlotError> cairo_checked(cairo_status_t status, const std::filesystem::path& path) {
  if (status == CAIRO_STATUS_SUCCESS) return {};
  return write_failed(path, cairo_status_to_string(status));
}

// Draws on @p surface and reports cairo's verdict (an error status sticks to the surface or the
// context).
Result<void, PlotError> render(cairo_surface_t* surface, const PlotSpec& spec,
                               const std::filesystem::path& path) {
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

// cairo names the top-level group after a process-wide surface counter ("surface83"); a fixed name
// makes the bytes depend on the spec only. Nothing else in our output references that id.
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
    case PlotError::Code::EMPTY:
      return "empty";
    case PlotError::Code::BAD_SERIES:
      return "bad_series";
    case PlotError::Code::BAD_SPEC:
      return "bad_spec";
    case PlotError::Code::WRITE_FAILED:
      return "write_failed";
  }
  return "unknown";
}

std::string PlotError::to_string() const {
  return std::string(evaluation::to_string(code)) + ": " + message;
}

Result<void, PlotError> validate_plot(const PlotSpec& spec) {
  const auto side_ok = [](int v) { return v >= MIN_PLOT_SIDE && v <= MAX_PLOT_SIDE; };
  if (!side_ok(spec.width) || !side_ok(spec.height)) {
    const std::string limits =
        "[" + std::to_string(MIN_PLOT_SIDE) + ", " + std::to_string(MAX_PLOT_SIDE) + "]";
    return fail(PlotError::Code::BAD_SPEC, "plot '" + spec.title + "': size " +
                                               std::to_string(spec.width) + "x" +
                                               std::to_string(spec.height) + " outside " + limits);
  }
  const bool lo_ok = !spec.y_min || std::isfinite(*spec.y_min),
             hi_ok = !spec.y_max || std::isfinite(*spec.y_max);
  if (!lo_ok || !hi_ok || (spec.y_min && spec.y_max && !(*spec.y_min < *spec.y_max))) {
    return fail(PlotError::Code::BAD_SPEC,
                "plot '" + spec.title + "': fixed y range not finite or not y_min < y_max");
  }
  bool any_point = false;
  for (std::size_t i = 0; i < spec.series.size(); ++i) {
    if (auto r = check_series(spec.series[i], i); !r) return r;
    any_point = any_point || !spec.series[i].x.empty();
  }
  if (!any_point)
    return fail(PlotError::Code::EMPTY,
                "plot '" + spec.title + "': no series with a point to draw");
  if (auto frame_result = make_frame(spec); !frame_result) return err(frame_result.error());
  return {};
}

Result<void, PlotError> write_plot_png(const PlotSpec& spec, const std::filesystem::path& path) {
  if (auto r = validate_plot(spec); !r) return r;
  const SurfacePtr surface(cairo_image_surface_create(CAIRO_FORMAT_ARGB32, spec.width, spec.height),
                           cairo_surface_destroy);
  if (auto r = render(surface.get(), spec, path); !r) return r;
  std::string png;  // encoded in memory: the file is written whole, or not at all
  if (auto r = cairo_checked(
          cairo_surface_write_to_png_stream(surface.get(), append_to_string, &png), path);
      !r)
    return r;
  if (auto written = core::write_whole_file(path, png); !written)
    return write_failed(path, written.error().c_str());
  return {};
}

Result<void, PlotError> write_plot_svg(const PlotSpec& spec, const std::filesystem::path& path) {
  if (auto r = validate_plot(spec); !r) return r;
  std::string
      svg;  // rendered in memory first: the file is written whole, or not at all on a cairo error
  {
    const SurfacePtr surface(
        cairo_svg_surface_create_for_stream(append_to_string, &svg, spec.width, spec.height),
        cairo_surface_destroy);
    if (auto r = render(surface.get(), spec, path); !r) return r;
    cairo_surface_finish(surface.get());
    if (auto r = cairo_checked(cairo_surface_status(surface.get()), path); !r) return r;
  }
  fix_surface_id(svg);
  if (auto written = core::write_whole_file(path, svg); !written)
    return write_failed(path, written.error().c_str());
  return {};
}

}  // namespace orthoflow::evaluation
