#pragma once
/// @file
/// @brief Depth-to-colour registration of the Kinect v1 (specs/KINECT_V1.md 8.3): the depth image
/// in millimetres re-projected into the RGB camera's 640x480 image, what libfreenect delivers as
/// FREENECT_DEPTH_REGISTERED.
///
/// The algorithm (facts taken from libfreenect's src/registration.c, identical in 0.5.3 and
/// master for the parts used here; this is an independent implementation):
/// - a per-pixel table from the 29 registration words: an incremental fixed-point evaluation of a
///   cubic polynomial (int64 accumulators, 2^-17 pixel units), plus one pixel in x and y. Where the
///   displaced pixel leaves the image the entry is invalid; otherwise it holds x in 1/256 pixel
///   and the whole row;
/// - a per-depth horizontal shift in 1/256 pixel: (baseline_px x (z_px - ref_px) / z_px + 0.375)
///   x 256, with pixel size 1 / (ref_pix x 2 x 10) (the zero plane is defined at 1280 px);
/// - per valid depth pixel: column = (x_fixed + shift[mm]) / 256 (truncated toward zero), row
///   from the table, the target moved up by 480 x start_lines (libfreenect's offset, sic); the
///   nearest depth wins where several pixels land on one target (z-buffer).
///
/// Depth in millimetres comes from drivers/kinect/kinect_depth.hpp (make_depth_table_mm), which
/// equals libfreenect's table; 10000 mm and more are dropped, as libfreenect does.
///
/// Known difference from libfreenect: an invalid table entry is always dropped. libfreenect keeps
/// it at x = 1280 px with its unchecked row, so a shift below -640 px (never produced by a
/// plausible calibration: about -32 px at 318 mm, the nearest reading) would bring it back into
/// the image, possibly writing outside the output buffer.
#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>
#include <vector>

#include "core/result.hpp"
#include "drivers/kinect/kinect_depth.hpp"
#include "drivers/kinect/kinect_protocol.hpp"

namespace orthoflow::drivers::kinect {

inline constexpr std::size_t REGISTERED_WIDTH = 640;
inline constexpr std::size_t REGISTERED_HEIGHT = 480;
inline constexpr std::size_t REGISTERED_PIXELS = REGISTERED_WIDTH * REGISTERED_HEIGHT;
inline constexpr std::int32_t SUBPIXELS = 256;             ///< fixed point: 1/256 pixel in x
inline constexpr std::uint16_t REGISTERED_MAX_MM = 10000;  ///< depths at or past this are dropped

/// @brief The precomputed registration of one camera: built once from its Calibration, then
/// applied to every frame.
/// @note Movable, not shared-mutable: register_depth is const, so one Registration may serve
/// several threads at once. Deterministic: the same calibration and frame give the same bits.
class Registration {
 public:
  /// @brief Why a calibration was refused.
  enum class Error : std::uint8_t {
    NOT_FINITE,    ///< a zero-plane value is NaN or infinite
    OUT_OF_RANGE,  ///< reference distance or pixel size is not positive
  };

  /// @brief Builds the tables (about 2.5 MB; the only allocation). Any 29 registration words and
  /// any pad info are accepted (the accumulators cannot overflow and every target is bounds
  /// checked); shifts beyond +-2^16 pixels are clamped, which changes no output pixel.
  /// @pre none. @note Allocates; call at start-up.
  [[nodiscard]] static Result<Registration, Error> create(const Calibration& calibration);

  /// @brief Registers one depth frame: @p raw (640x480 raw disparities) into @p registered_mm
  /// (640x480 millimetres in the RGB image, 0 = no depth). Raw 2047 and anything above it, and
  /// depths with no millimetre value, are no reading.
  /// @pre raw.size() == registered_mm.size() == REGISTERED_PIXELS (OF_ENFORCE).
  /// @note No allocation; two passes of 640x480 steps. Thread-safe (const).
  void register_depth(std::span<const std::uint16_t> raw,
                      std::span<std::uint16_t> registered_mm) const noexcept;

  /// @brief The millimetres register_depth uses for @p raw: make_depth_table_mm's value, 0 for no
  /// reading (2047 and above, past the pole, 10000 mm and more). @pre none.
  [[nodiscard]] std::uint16_t depth_mm(std::uint16_t raw) const noexcept;

  /// @brief The horizontal shift, in 1/256 pixel, of a point @p mm millimetres away (0 for 0 and
  /// for REGISTERED_MAX_MM and above). @pre none.
  [[nodiscard]] std::int32_t shift_fixed(std::uint16_t mm) const noexcept;

  /// @brief Where depth pixel (@p x, @p y) at @p mm lands in the output (row-major index), or
  /// nullopt if it leaves the image or @p mm is not a reading. @pre none.
  [[nodiscard]] std::optional<std::size_t> target_index(std::size_t x, std::size_t y,
                                                        std::uint16_t mm) const noexcept;

 private:
  /// One depth pixel's rectified position: x in 1/256 pixel (INT32_MIN: outside the image), whole
  /// row.
  struct PixelTarget {
    std::int32_t x_fixed = 0;
    std::int32_t row = 0;
  };

  Registration() = default;
  /// The per-pixel table from the registration words (the polynomial's forward differences).
  static void fill_pixels(const RegInfo& reg, std::span<PixelTarget> pixels) noexcept;

  std::vector<PixelTarget> pixels_;   // REGISTERED_PIXELS entries, row-major
  std::vector<std::int32_t> shifts_;  // REGISTERED_MAX_MM entries, index = mm
  DepthTableMm mm_{};                 // raw -> mm, 0 = no reading
  std::int64_t target_offset_ = 0;    // 480 x start_lines, subtracted from every target index
};

/// @brief Lower-case name of @p error, e.g. "not_finite". @pre none.
[[nodiscard]] const char* to_string(Registration::Error error) noexcept;

}  // namespace orthoflow::drivers::kinect
