#pragma once
/// @file
/// @brief The TUM RGB-D benchmark's folder layout (vision.in.tum.de/data/datasets/rgbd-dataset,
/// "File Formats"), which many Kinect v1 recordings use:
/// - `depth/<t>.png`: 640 x 480 16-bit greyscale PNG, 5000 units per metre, 0 = no reading
///   (formats/png_depth.hpp reads it);
/// - `depth.txt`: "# ..." comment lines, then one "<timestamp> <file>" line per depth image;
/// - `associate.txt` (optional, written by the benchmark's associate.py): one
///   "<timestamp> <file> <timestamp> <file> ..." line per matched colour and depth pair, in
///   either order; the depth file is the one under `depth/`.
/// Timestamps are capture times in seconds since the Unix epoch. When both listings exist,
/// associate.txt is used (its frames have a colour match). The files a listing names must be
/// relative PNG paths inside the folder; anything else is an error naming the line. A line whose
/// timestamp is not later than the previous one is skipped and counted, never reordered.
#include <cstddef>
#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

#include "core/result.hpp"
#include "formats/io_error.hpp"

namespace orthoflow::formats {

inline constexpr double TUM_DEPTH_UNITS_PER_METRE = 5000.0;
inline constexpr std::uint32_t TUM_WIDTH = 640;
inline constexpr std::uint32_t TUM_HEIGHT = 480;

/// @brief One depth image of a listing.
struct TumDepthEntry {
  double seconds = 0.0;  ///< capture time, seconds since the Unix epoch
  std::string file;      ///< relative to the folder, e.g. "depth/1305031102.160407.png"
};

/// @brief A folder's depth images in capture order.
struct TumDepthList {
  std::vector<TumDepthEntry> entries;
  std::size_t out_of_order = 0;  ///< lines skipped: not later than the line before
  std::string listing;           ///< "associate.txt" or "depth.txt"
};

/// @brief Parses a listing held in memory (@p associated: associate.txt's columns, else
/// depth.txt's); @p name names it in errors. (The reader's core; fuzzed.) @note Allocates.
[[nodiscard]] Result<TumDepthList, IoError> parse_tum_depth_list(std::string_view text,
                                                                 const std::string& name,
                                                                 bool associated);

/// @brief Reads @p dir's associate.txt, else its depth.txt. An empty listing is an error.
[[nodiscard]] Result<TumDepthList, IoError> read_tum_depth_list(const std::filesystem::path& dir);

}  // namespace orthoflow::formats
