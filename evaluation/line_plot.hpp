#pragma once
/// @file
/// @brief Line plots of evaluation curves (accuracy vs. iterations, learning curves, ...) written
/// as PNG or SVG with cairo. One drawing routine serves both surfaces: white background, axes with
/// 1/2/5 x 10^k ticks, light grey grid, title, axis labels, one Okabe-Ito colour per series,
/// optional markers and error bars, and a legend in the corner that covers the fewest data points.
#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "core/result.hpp"

namespace orthoflow::evaluation {

/// @brief One curve: points (x[i], y[i]), drawn as a polyline in the order given.
struct Series {
  std::string name;          ///< legend entry; an empty name gives no legend row
  std::vector<double> x, y;  ///< same size; every value finite
  std::vector<double>
      y_err;  ///< empty, or same size as y: half-length of an error bar (e.g. std over runs), >= 0
  bool markers = true;  ///< draw a filled circle at each point
};

/// @brief What to draw and how large.
struct PlotSpec {
  std::string title, x_label, y_label;
  std::vector<Series> series;
  std::optional<double> y_min,
      y_max;  ///< fixed y range (e.g. 0..1 for accuracy); missing ends come from the data
  int width = 800, height = 500;  ///< pixels (PNG) or points (SVG), each in [MIN_SIDE, MAX_SIDE]
};

/// @brief Smallest and largest accepted PlotSpec::width / height.
inline constexpr int MIN_PLOT_SIDE = 200;
inline constexpr int MAX_PLOT_SIDE = 8192;

/// @brief Why a plot was not written, and what/where.
struct PlotError {
  enum class Code : std::uint8_t {
    EMPTY,       ///< no series, or no series with at least one point
    BAD_SERIES,  ///< x/y/y_err size mismatch, a non-finite or negative-error value, or a data range
                 ///< overflowing
    BAD_SPEC,    ///< width/height out of range, or y_min/y_max non-finite or not y_min < y_max
    WRITE_FAILED,  ///< cairo could not create or write the file
  };
  Code code = Code::EMPTY;
  std::string
      message;  ///< e.g. "series 'nbc' (#1): y[7] is nan" or "cannot write '/x/plot.png': ..."

  /// @brief "<code name>: <message>".
  [[nodiscard]] std::string to_string() const;
};

/// @brief The enumerator's name in lower case, e.g. "bad_series".
[[nodiscard]] const char* to_string(PlotError::Code code) noexcept;

/// @brief Checks @p spec without drawing: the errors write_plot_png/svg would return before
/// touching a file.
[[nodiscard]] Result<void, PlotError> validate_plot(const PlotSpec& spec);

/// @brief Draws @p spec and writes it as a PNG file (ARGB32) of spec.width x spec.height pixels.
/// @pre none: a bad spec gives EMPTY / BAD_SERIES / BAD_SPEC and no file is created.
/// @note Thread-safe for distinct paths (no shared state besides cairo's own, which is
/// thread-safe).
[[nodiscard]] Result<void, PlotError> write_plot_png(const PlotSpec& spec,
                                                     const std::filesystem::path& path);

/// @brief Draws @p spec and writes it as an SVG file of spec.width x spec.height points.
/// @pre none: a bad spec gives EMPTY / BAD_SERIES / BAD_SPEC and no file is created.
/// @note Deterministic: the same spec gives the same bytes. Text is written as glyph outlines
/// (cairo 1.16).
[[nodiscard]] Result<void, PlotError> write_plot_svg(const PlotSpec& spec,
                                                     const std::filesystem::path& path);

}  // namespace orthoflow::evaluation
