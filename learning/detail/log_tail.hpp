#pragma once
/// @file
/// @brief Checks the tail of a store's LevelDB write-ahead log before LevelDB replays it. LevelDB
/// stops quietly at a record cut short at the end of the log (it takes it for a write the crash
/// interrupted), so a synced, acknowledged teach whose bytes were later lost from the tail would
/// vanish without a word; paranoid checks catch only checksum mismatches. The check walks the
/// documented log format (LevelDB doc/log_format.md: 32 KiB blocks of records, each a 7-byte header
/// of masked CRC32C, 16-bit length and type FULL/FIRST/MIDDLE/LAST, blocks padded with zeros) and
/// reports a tail that does not end on a whole record. Internal to learning/.
#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>

namespace orthoflow::learning {

/// @brief A write-ahead log whose end is not a whole record.
struct LogTailDamage {
  std::filesystem::path file;       ///< the log file
  std::uint64_t dropped_bytes = 0;  ///< bytes after the last whole record
  std::string reason;               ///< e.g. "a record of 4120 bytes is cut short after 310 bytes"
  /// @brief One sentence for the user.
  [[nodiscard]] std::string to_string() const;
};

/// @brief The damage at the end of one log file, if any (a file that cannot be read is not damage:
/// LevelDB reports it).
[[nodiscard]] std::optional<LogTailDamage> check_log_tail(const std::filesystem::path& file);

/// @brief The damage at the end of the newest write-ahead log (*.log) of the store @p dir, if any.
[[nodiscard]] std::optional<LogTailDamage> check_store_log(const std::filesystem::path& dir);

}  // namespace orthoflow::learning
