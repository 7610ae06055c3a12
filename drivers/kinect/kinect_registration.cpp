#include "drivers/kinect/kinect_registration.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "core/assert.hpp"

namespace orthoflow::drivers::kinect {
namespace {

constexpr std::int32_t X_INVALID = std::numeric_limits<std::int32_t>::min();
// |shift| beyond 2^16 px can never land inside a 640 px row, so clamping there changes nothing.
constexpr double SHIFT_LIMIT_FIXED = 16777216.0;  // 2^24 = 2^16 px in 1/256 px
constexpr double POLY_UNIT = 1.0 / 131072.0;      // the accumulators count 2^-17 pixel

// Indices of RegInfo::words (reg_info_name order; checked by the unit test).
enum Word : std::size_t {
  AX = 1,
  BX = 2,
  CX = 3,
  DX = 4,
  DX_START = 5,
  AY = 6,
  BY = 7,
  CY = 8,
  DY = 9,
  DY_START = 10,
  DXDX_START = 17,
  DXDY_START = 18,
  DYDX_START = 19,
  DYDY_START = 20,
  DXDXDX_START = 21,
  DYDXDX_START = 22,
  DXDXDY_START = 23,
  DYDXDY_START = 24,
  DYDYDX_START = 26,
  DYDYDY_START = 28,
};

// A 32-bit shift left that wraps (the device words are scaled in 32 bits before widening, which
// clamps out-of-range words exactly as the reference does), then an arithmetic shift right.
std::int64_t scaled_start(std::int32_t word, unsigned left, unsigned right) noexcept {
  const auto wrapped = static_cast<std::int32_t>(static_cast<std::uint32_t>(word) << left);
  return static_cast<std::int64_t>(wrapped >> right);
}

// The words of one output axis (x or y displacement) of the cubic displacement polynomial.
struct AxisWords {
  std::int32_t col_col_col_step;  // added per column to the second column difference (a)
  std::int32_t row_row_row_step;  // added per row to the second row difference (b)
  std::int32_t col_col_row_step;  // added per row to the second column difference (c)
  std::int32_t row_col_row_step;  // added per row to the mixed difference (d)
  std::int32_t value, col, row, col_col, row_col, row_row;  // the *_start words
};

AxisWords axis_words(const RegInfo& reg, bool y_axis) noexcept {
  const auto& w = reg.words;
  if (!y_axis) {
    return {w[AX],         w[BX],         w[CX],           w[DX],           w[DX_START],
            w[DXDX_START], w[DYDX_START], w[DXDXDX_START], w[DYDXDX_START], w[DYDYDX_START]};
  }
  return {w[AY],         w[BY],         w[CY],           w[DY],           w[DY_START],
          w[DXDY_START], w[DYDY_START], w[DXDXDY_START], w[DYDXDY_START], w[DYDYDY_START]};
}

// Forward differences of one axis, advanced row by row (int64: cannot overflow for any words,
// the largest magnitude after 480 rows and 640 columns stays below 2^47).
struct AxisRows {
  std::int64_t value, col, row, col_col, row_col, row_row;

  explicit AxisRows(const AxisWords& w) noexcept
      : value(scaled_start(w.value, 13, 4)),
        col(scaled_start(w.col, 11, 3)),
        row(scaled_start(w.row, 11, 3)),
        col_col(scaled_start(w.col_col, 8, 0)),
        row_col(scaled_start(w.row_col, 8, 0)),
        row_row(scaled_start(w.row_row, 8, 0)) {}

  // The reference advances before the first row is used; the order of the updates matters.
  void next_row(const AxisWords& w) noexcept {
    col_col += w.col_col_row_step;
    col += row_col >> 8;
    row_col += w.row_col_row_step;
    value += row >> 6;
    row += row_row >> 8;
    row_row += w.row_row_row_step;
  }
};

// One row's walk along the columns.
struct AxisCols {
  std::int64_t value, col, col_col;
  explicit AxisCols(const AxisRows& r) noexcept : value(r.value), col(r.col), col_col(r.col_col) {}
  void next_col(const AxisWords& w) noexcept {
    value += col >> 6;
    col += col_col >> 8;
    col_col += w.col_col_col_step;
  }
};

// 1/256 pixel shift of every depth in mm; the float product is the reference's own precision.
void fill_shifts(const ZeroPlane& zp, std::span<std::int32_t> shifts) noexcept {
  const float pixel_scale = zp.reference_pixel_size_mm * 2.0F * 10.0F;  // 1280 px zero plane
  const double pixel_size = 1.0 / static_cast<double>(pixel_scale);
  const double baseline_px = static_cast<double>(zp.dcmos_rcmos_dist_cm) * pixel_size * 10.0;
  const double reference_px = static_cast<double>(zp.reference_distance_mm) * pixel_size * 10.0;
  shifts[0] = 0;  // 0 mm is "no reading" and never looked up
  for (std::size_t mm = 1; mm < shifts.size(); ++mm) {
    const double depth_px = static_cast<double>(mm) * pixel_size;
    double v = (baseline_px * (depth_px - reference_px) / depth_px + 0.375) * SUBPIXELS;
    if (!std::isfinite(v)) v = SHIFT_LIMIT_FIXED;  // unreachable for a refused-or-valid input
    shifts[mm] = static_cast<std::int32_t>(std::clamp(v, -SHIFT_LIMIT_FIXED, SHIFT_LIMIT_FIXED));
  }
}

}  // namespace

Result<Registration, Registration::Error> Registration::create(const Calibration& calibration) {
  const ZeroPlane& zp = calibration.zero_plane;
  if (!std::isfinite(zp.dcmos_emitter_dist_cm) || !std::isfinite(zp.dcmos_rcmos_dist_cm) ||
      !std::isfinite(zp.reference_distance_mm) || !std::isfinite(zp.reference_pixel_size_mm)) {
    return err(Error::NOT_FINITE);
  }
  const float pixel_scale = zp.reference_pixel_size_mm * 2.0F * 10.0F;
  if (!(zp.reference_distance_mm > 0.0F) || !(pixel_scale > 0.0F) || !std::isfinite(pixel_scale)) {
    return err(Error::OUT_OF_RANGE);
  }
  Registration reg;
  reg.pixels_.resize(REGISTERED_PIXELS);
  reg.shifts_.resize(REGISTERED_MAX_MM);
  fill_shifts(zp, reg.shifts_);
  reg.mm_ = make_depth_table_mm(calibration);
  for (std::uint16_t& mm : reg.mm_) mm = mm >= REGISTERED_MAX_MM ? std::uint16_t{0} : mm;
  reg.target_offset_ = static_cast<std::int64_t>(REGISTERED_HEIGHT) * calibration.pad.start_lines;
  fill_pixels(calibration.reg, reg.pixels_);
  return reg;
}

void Registration::fill_pixels(const RegInfo& words, std::span<PixelTarget> pixels) noexcept {
  const AxisWords wx = axis_words(words, false);
  const AxisWords wy = axis_words(words, true);
  AxisRows rx(wx);
  AxisRows ry(wy);
  constexpr double WIDTH = static_cast<double>(REGISTERED_WIDTH);
  constexpr double HEIGHT = static_cast<double>(REGISTERED_HEIGHT);
  for (std::size_t y = 0; y < REGISTERED_HEIGHT; ++y) {
    rx.next_row(wx);
    ry.next_row(wy);
    AxisCols cx(rx);
    AxisCols cy(ry);
    for (std::size_t x = 0; x < REGISTERED_WIDTH; ++x) {
      // Displacement plus the fixed one-pixel offset, in the reference's order of operations.
      const double new_x = static_cast<double>(x) + static_cast<double>(cx.value) * POLY_UNIT + 1.0;
      const double new_y = static_cast<double>(y) + static_cast<double>(cy.value) * POLY_UNIT + 1.0;
      PixelTarget& t = pixels[y * REGISTERED_WIDTH + x];
      if (new_x < 0.0 || new_y < 0.0 || new_x >= WIDTH || new_y >= HEIGHT) {
        t = {X_INVALID, 0};
      } else {
        t = {static_cast<std::int32_t>(new_x * SUBPIXELS), static_cast<std::int32_t>(new_y)};
      }
      cx.next_col(wx);
      cy.next_col(wy);
    }
  }
}

std::uint16_t Registration::depth_mm(std::uint16_t raw) const noexcept {
  return raw < mm_.size() ? mm_[raw] : std::uint16_t{0};
}

std::int32_t Registration::shift_fixed(std::uint16_t mm) const noexcept {
  return mm < shifts_.size() ? shifts_[mm] : 0;
}

std::optional<std::size_t> Registration::target_index(std::size_t x, std::size_t y,
                                                      std::uint16_t mm) const noexcept {
  if (x >= REGISTERED_WIDTH || y >= REGISTERED_HEIGHT || mm == 0 || mm >= REGISTERED_MAX_MM) {
    return std::nullopt;
  }
  const PixelTarget& t = pixels_[y * REGISTERED_WIDTH + x];
  if (t.x_fixed == X_INVALID) return std::nullopt;
  // Signed division truncates toward zero, so sums in (-256, 0) land in column 0, as in the
  // reference (whose unsigned range check then accepts them).
  const std::int64_t column = (static_cast<std::int64_t>(t.x_fixed) + shifts_[mm]) / SUBPIXELS;
  if (column < 0 || column >= static_cast<std::int64_t>(REGISTERED_WIDTH)) return std::nullopt;
  const std::int64_t index =
      static_cast<std::int64_t>(t.row) * static_cast<std::int64_t>(REGISTERED_WIDTH) + column -
      target_offset_;
  if (index < 0 || index >= static_cast<std::int64_t>(REGISTERED_PIXELS)) return std::nullopt;
  return static_cast<std::size_t>(index);
}

void Registration::register_depth(std::span<const std::uint16_t> raw,
                                  std::span<std::uint16_t> registered_mm) const noexcept {
  OF_ENFORCE(raw.size() == REGISTERED_PIXELS, "register_depth: raw must be 640x480");
  OF_ENFORCE(registered_mm.size() == REGISTERED_PIXELS, "register_depth: output must be 640x480");
  std::fill(registered_mm.begin(), registered_mm.end(), std::uint16_t{0});
  for (std::size_t y = 0; y < REGISTERED_HEIGHT; ++y) {
    for (std::size_t x = 0; x < REGISTERED_WIDTH; ++x) {
      const std::uint16_t mm = depth_mm(raw[y * REGISTERED_WIDTH + x]);
      const std::optional<std::size_t> maybe_target = target_index(x, y, mm);
      if (!maybe_target) continue;
      std::uint16_t& current = registered_mm[*maybe_target];
      if (current == 0 || current > mm) current = mm;  // z-buffer: the nearest wins
    }
  }
}

const char* to_string(Registration::Error error) noexcept {
  switch (error) {
    case Registration::Error::NOT_FINITE:
      return "not_finite";
    case Registration::Error::OUT_OF_RANGE:
      return "out_of_range";
  }
  return "unknown";
}

}  // namespace orthoflow::drivers::kinect
