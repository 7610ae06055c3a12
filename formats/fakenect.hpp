#pragma once
/// @file
/// @brief libfreenect's fakenect recording format (specs/USB_TESTING.md section 2), so recordings
/// move both ways between orthoflow and libfreenect's `fakenect-record` / `fakenect` tools:
/// - `INDEX.txt`: one file name per line, in recording order (the replay schedule);
/// - `d-<host_s>-<dev_ts>.pgm`: "P5 640 480 65535\n" then 640 x 480 raw 11-bit disparities as
///   host-order (little-endian) u16, as fakenect writes them (not PGM's big-endian);
/// - `r-<host_s>-<dev_ts>.ppm`: "P6 640 480 255\n" then 640 x 480 RGB24;
/// - `a-<host_s>-<dev_ts>.dump`: the 12-byte freenect_raw_tilt_state (int16 accel x, y, z; int8
///   tilt in half degrees; a pad byte; int32 status), little-endian;
/// - `device.json`: the registration parameters (optional: without it only raw replay works); it is
///   read and written with the driver's calibration in graphs/nodes/fakenect_calibration.hpp.
/// `<host_s>` is host wall-clock seconds with 6 decimals, `<dev_ts>` the 32-bit 60 MHz device time.
/// Readers are strict: a wrong header, size or value is an error naming the file, never a frame.
#include <array>
#include <cstdint>
#include <filesystem>
#include <span>
#include <string>
#include <vector>

#include "core/result.hpp"
#include "formats/io_error.hpp"

namespace orthoflow::formats {

inline constexpr std::uint32_t FAKENECT_WIDTH = 640;
inline constexpr std::uint32_t FAKENECT_HEIGHT = 480;
inline constexpr std::size_t FAKENECT_PIXELS = std::size_t{FAKENECT_WIDTH} * FAKENECT_HEIGHT;

/// @brief One INDEX.txt line.
struct FakenectEntry {
  char kind = 'd';          ///< 'd' depth, 'r' colour, 'a' accelerometer
  double host_seconds = 0;  ///< from the name
  std::uint32_t device_ticks = 0;
  std::string file;  ///< the name as listed (relative to the directory)
};

/// @brief The file name of a record, e.g. "d-1234.500000-2000000.pgm".
[[nodiscard]] std::string fakenect_name(char kind, double host_seconds, std::uint32_t device_ticks);
/// @brief Parses INDEX.txt of @p dir. Lines whose name does not follow the pattern are an error
/// naming the line; an empty index is an error. @note Allocates.
[[nodiscard]] Result<std::vector<FakenectEntry>, IoError> read_fakenect_index(
    const std::filesystem::path& dir);

/// @brief Writes a depth record (raw values > 2047 are refused: they are not Kinect disparities).
[[nodiscard]] Result<void, IoError> write_fakenect_depth(const std::filesystem::path& path,
                                                         std::span<const std::uint16_t> raw);
/// @brief Reads a depth record into @p raw (FAKENECT_PIXELS values). @pre raw.size() ==
/// FAKENECT_PIXELS.
[[nodiscard]] Result<void, IoError> read_fakenect_depth(const std::filesystem::path& path,
                                                        std::span<std::uint16_t> raw);
/// @brief Parses a depth record held in memory (the reader's core; fuzzed).
[[nodiscard]] Result<void, IoError> parse_fakenect_depth(std::span<const char> bytes,
                                                         const std::string& name,
                                                         std::span<std::uint16_t> raw);
/// @brief Writes a colour record. @pre rgb.size() == 3 x FAKENECT_PIXELS.
[[nodiscard]] Result<void, IoError> write_fakenect_rgb(const std::filesystem::path& path,
                                                       std::span<const std::uint8_t> rgb);
/// @brief Reads a colour record into @p rgb. @pre rgb.size() == 3 x FAKENECT_PIXELS.
[[nodiscard]] Result<void, IoError> read_fakenect_rgb(const std::filesystem::path& path,
                                                      std::span<std::uint8_t> rgb);

/// @brief freenect_raw_tilt_state as fakenect dumps it.
struct FakenectTilt {
  std::int16_t accel_x = 0, accel_y = 0, accel_z = 0;
  std::int8_t tilt_half_degrees = 0;
  std::int32_t status = 0;
};
[[nodiscard]] Result<void, IoError> write_fakenect_tilt(const std::filesystem::path& path,
                                                        const FakenectTilt& tilt);
[[nodiscard]] Result<FakenectTilt, IoError> read_fakenect_tilt(const std::filesystem::path& path);

}  // namespace orthoflow::formats
