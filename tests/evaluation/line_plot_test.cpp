// Line plots (evaluation/line_plot.hpp): PNG decodes with the series colours in the plot, SVG
// structure and byte-for-byte determinism, degenerate data that must still draw, and every
// PlotError code.
#include "evaluation/line_plot.hpp"

#include <cairo.h>
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <limits>
#include <memory>
#include <string>

namespace orthoflow::evaluation {
namespace {

namespace fs = std::filesystem;

// One folder per test: ctest runs the discovered tests in parallel processes.
fs::path out_dir() {
  const fs::path dir = fs::path(ORTHOFLOW_BINARY_DIR) / "line_plot_test_out" /
                       ::testing::UnitTest::GetInstance()->current_test_info()->name();
  fs::create_directories(dir);
  return dir;
}

std::string read_all(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

PlotSpec accuracy_spec() {
  PlotSpec spec;
  spec.title = "Accuracy vs. question/correction iterations";
  spec.x_label = "iterations";
  spec.y_label = "accuracy";
  spec.y_min = 0.0, spec.y_max = 1.0;
  spec.width = 640, spec.height = 400;
  spec.series.push_back(
      {"instance-based", {0, 10, 20, 30, 40}, {0.3, 0.3, 0.3, 0.3, 0.3}, {}, false});
  spec.series.push_back({"bayesian",
                         {0, 10, 20, 30, 40},
                         {0.7, 0.7, 0.7, 0.7, 0.7},
                         {0.05, 0.05, 0.1, 0.02, 0},
                         true});
  return spec;
}

// Pixels of column x whose colour is within 1 per channel of (r, g, b).
int count_in_column(cairo_surface_t* img, int x, std::uint32_t r, std::uint32_t g,
                    std::uint32_t b) {
  const unsigned char* data = cairo_image_surface_get_data(img);
  const int stride = cairo_image_surface_get_stride(img);
  const auto near = [](std::uint32_t a, std::uint32_t want) {
    return (a > want ? a - want : want - a) <= 1;
  };
  int hits = 0;
  for (int y = 0; y < cairo_image_surface_get_height(img); ++y) {
    std::uint32_t px = 0;
    std::memcpy(&px, data + static_cast<std::ptrdiff_t>(y) * stride + x * 4,
                4);  // ARGB32, native endian
    hits += near((px >> 16) & 0xFF, r) && near((px >> 8) & 0xFF, g) && near(px & 0xFF, b) ? 1 : 0;
  }
  return hits;
}

TEST(LinePlot, PngDecodesWithSizeBackgroundAndSeriesColours) {
  const fs::path path = out_dir() / "accuracy.png";
  const auto write_result = write_plot_png(accuracy_spec(), path);
  ASSERT_TRUE(write_result) << write_result.error().to_string();
  const std::unique_ptr<cairo_surface_t, decltype(&cairo_surface_destroy)> img(
      cairo_image_surface_create_from_png(path.c_str()), cairo_surface_destroy);
  ASSERT_EQ(cairo_surface_status(img.get()), CAIRO_STATUS_SUCCESS);
  EXPECT_EQ(cairo_image_surface_get_width(img.get()), 640);
  EXPECT_EQ(cairo_image_surface_get_height(img.get()), 400);
  // The flat series cross the middle column (the legend sits in a corner): Okabe-Ito blue, then
  // vermillion.
  EXPECT_GE(count_in_column(img.get(), 320, 0, 114, 178), 1);
  EXPECT_GE(count_in_column(img.get(), 320, 213, 94, 0), 1);
  EXPECT_EQ(count_in_column(img.get(), 320, 0, 158, 115), 0);  // the third colour: no third series
  EXPECT_GT(count_in_column(img.get(), 2, 255, 255, 255), 390);  // white margin
}

TEST(LinePlot, SvgIsWellFormedAndCarriesTheTitleGlyphs) {
  const fs::path dir = out_dir();
  PlotSpec spec = accuracy_spec();
  ASSERT_TRUE(write_plot_svg(spec, dir / "with_title.svg"));
  spec.title.clear();
  ASSERT_TRUE(write_plot_svg(spec, dir / "without_title.svg"));
  const std::string with_title = read_all(dir / "with_title.svg"),
                    without = read_all(dir / "without_title.svg");
  EXPECT_EQ(with_title.rfind("<?xml", 0), 0u);
  EXPECT_NE(with_title.find("<svg"), std::string::npos);
  EXPECT_NE(with_title.find("width=\"640pt\""), std::string::npos);
  EXPECT_NE(with_title.find("</svg>"), std::string::npos);
  EXPECT_NE(with_title.find("glyph"),
            std::string::npos);                        // cairo 1.16 writes text as glyph symbols
  EXPECT_GT(with_title.size(), without.size() + 200);  // the title's glyphs and their uses
}

TEST(LinePlot, SvgBytesAreDeterministic) {
  const fs::path dir = out_dir();
  ASSERT_TRUE(write_plot_svg(accuracy_spec(), dir / "a.svg"));
  ASSERT_TRUE(write_plot_svg(accuracy_spec(), dir / "b.svg"));
  EXPECT_EQ(read_all(dir / "a.svg"), read_all(dir / "b.svg"));
  PlotSpec other = accuracy_spec();
  other.series[1].y[2] = 0.75;
  ASSERT_TRUE(write_plot_svg(other, dir / "c.svg"));
  EXPECT_NE(read_all(dir / "a.svg"), read_all(dir / "c.svg"));
}

TEST(LinePlot, DegenerateButValidDataDraws) {
  const fs::path dir = out_dir();
  PlotSpec spec;
  spec.series.push_back({"one point", {3.0}, {0.25}, {}, true});
  EXPECT_TRUE(write_plot_png(spec, dir / "single.png"));
  spec.series[0] = {"flat", {0, 1, 2}, {5, 5, 5}, {}, true};  // all-equal y: range padded
  spec.series.push_back({"empty alongside data", {}, {}, {}, true});
  EXPECT_TRUE(write_plot_svg(spec, dir / "flat.svg"));
  spec.series[0] = {"zeros", {0, 0}, {0, 0}, {}, true};  // one x, one y, both zero
  EXPECT_TRUE(write_plot_png(spec, dir / "zeros.png"));
  spec.series[0] = {"huge", {-1e300, 1e300}, {1e-300, 2e-300}, {}, true};
  EXPECT_TRUE(write_plot_png(spec, dir / "huge.png"));
  spec = accuracy_spec();
  spec.series[0].y = {-3, 4, 0.5, 0.5, 2};  // beyond the fixed 0..1: clipped to the frame
  spec.y_max.reset();                       // y_min fixed only
  EXPECT_TRUE(write_plot_png(spec, dir / "clipped.png"));
  for (int i = 0; i < 11; ++i) {  // more series than palette colours: dashed repeats
    spec.series.push_back({"s" + std::to_string(i), {0, 1}, {0.1 * i, 0.05 * i}, {}, i % 2 == 0});
  }
  EXPECT_TRUE(write_plot_svg(spec, dir / "many.svg"));
}

TEST(LinePlot, EmptySpecIsEmpty) {
  const fs::path path = out_dir() / "empty.png";
  PlotSpec spec;
  auto result = write_plot_png(spec, path);
  ASSERT_FALSE(result);
  EXPECT_EQ(result.error().code, PlotError::Code::EMPTY);
  spec.series.resize(2);  // series without points
  result = write_plot_svg(spec, path);
  ASSERT_FALSE(result);
  EXPECT_EQ(result.error().code, PlotError::Code::EMPTY);
  EXPECT_EQ(result.error().to_string().rfind("empty: ", 0), 0u);
  EXPECT_FALSE(fs::exists(path));
}

void expect_bad_series(const PlotSpec& spec, const std::string& where) {
  const fs::path path = out_dir() / "bad.svg";
  const auto result = write_plot_svg(spec, path);
  ASSERT_FALSE(result) << where;
  EXPECT_EQ(result.error().code, PlotError::Code::BAD_SERIES) << result.error().to_string();
  EXPECT_NE(result.error().message.find(where), std::string::npos) << result.error().message;
  EXPECT_FALSE(fs::exists(path));  // nothing written for bad data
}

TEST(LinePlot, BadSeriesNamesTheSeriesAndValue) {
  constexpr double NAN_V = std::numeric_limits<double>::quiet_NaN(),
                   INF_V = std::numeric_limits<double>::infinity();
  PlotSpec spec = accuracy_spec();
  spec.series[1].x.pop_back();
  expect_bad_series(spec, "series 'bayesian' (#1): 4 x values but 5 y values");
  spec = accuracy_spec();
  spec.series[0].y[3] = NAN_V;
  expect_bad_series(spec, "series 'instance-based' (#0): y[3] is nan");
  spec = accuracy_spec();
  spec.series[1].x[0] = -INF_V;
  expect_bad_series(spec, "x[0] is -inf");
  spec = accuracy_spec();
  spec.series[1].y_err.pop_back();
  expect_bad_series(spec, "4 y_err values for 5 points");
  spec = accuracy_spec();
  spec.series[1].y_err[1] = -0.1;
  expect_bad_series(spec, "y_err[1] is -0.1");
  spec = accuracy_spec();
  spec.series[0].x = {-1.7e308, 1.7e308, 0, 1, 2};  // finite values whose range overflows
  expect_bad_series(spec, "x range");
}

TEST(LinePlot, BadSpecSizeOrRange) {
  const fs::path path = out_dir() / "spec.png";
  PlotSpec spec = accuracy_spec();
  spec.width = 0;
  auto result = write_plot_png(spec, path);
  ASSERT_FALSE(result);
  EXPECT_EQ(result.error().code, PlotError::Code::BAD_SPEC);
  EXPECT_NE(result.error().message.find("size 0x400"), std::string::npos) << result.error().message;
  spec.width = 100000;  // would be a 16 GB image
  EXPECT_EQ(write_plot_png(spec, path).error().code, PlotError::Code::BAD_SPEC);
  spec = accuracy_spec();
  spec.y_min = 1.0;  // == y_max
  EXPECT_EQ(write_plot_svg(spec, path).error().code, PlotError::Code::BAD_SPEC);
  spec.y_min = std::numeric_limits<double>::quiet_NaN();
  EXPECT_EQ(validate_plot(spec).error().code, PlotError::Code::BAD_SPEC);
  spec.y_min = 1e20,
  spec.y_max = 1e20 + 65536;  // ticks of 1e4 at 1e20: indices beyond exact doubles
  result = write_plot_png(spec, path);
  ASSERT_FALSE(result);
  EXPECT_EQ(result.error().code, PlotError::Code::BAD_SPEC);
  EXPECT_NE(result.error().message.find("y range [1e+20, 1e+20]"), std::string::npos)
      << result.error().message;
  EXPECT_FALSE(fs::exists(path));
}

TEST(LinePlot, UnwritablePathIsWriteFailedNamingThePath) {
  const fs::path dir = out_dir() / "no" / "such" / "dir";
  for (const bool svg : {false, true}) {
    const fs::path path = dir / (svg ? "plot.svg" : "plot.png");
    const auto result =
        svg ? write_plot_svg(accuracy_spec(), path) : write_plot_png(accuracy_spec(), path);
    ASSERT_FALSE(result);
    EXPECT_EQ(result.error().code, PlotError::Code::WRITE_FAILED);
    EXPECT_NE(result.error().message.find(path.string()), std::string::npos)
        << result.error().message;
  }
}

TEST(LinePlot, ErrorCodeNames) {
  EXPECT_STREQ(to_string(PlotError::Code::EMPTY), "empty");
  EXPECT_STREQ(to_string(PlotError::Code::BAD_SERIES), "bad_series");
  EXPECT_STREQ(to_string(PlotError::Code::BAD_SPEC), "bad_spec");
  EXPECT_STREQ(to_string(PlotError::Code::WRITE_FAILED), "write_failed");
}

}  // namespace
}  // namespace orthoflow::evaluation
