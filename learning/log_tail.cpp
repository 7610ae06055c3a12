#include "learning/detail/log_tail.hpp"

#include <algorithm>
#include <fstream>
#include <iterator>
#include <vector>

namespace orthoflow::learning {

namespace {

constexpr std::size_t BLOCK = 32768;  // LevelDB log::kBlockSize
constexpr std::size_t HEADER = 7;     // checksum (4), length (2), type (1)
enum RecordType : std::uint8_t { ZERO = 0, FULL = 1, FIRST = 2, MIDDLE = 3, LAST = 4 };

bool all_zero(const std::vector<unsigned char>& bytes, std::size_t from) {
  return std::all_of(bytes.begin() + static_cast<std::ptrdiff_t>(from), bytes.end(),
                     [](unsigned char b) { return b == 0; });
}

}  // namespace

std::string LogTailDamage::to_string() const {
  return "the write-ahead log " + file.filename().string() + " ends in " +
         std::to_string(dropped_bytes) + " bytes that are not a whole record (" + reason +
         "): the last write before a crash, or a damaged file; LevelDB drops them, so if they were "
         "an acknowledged teach, correct or forget, it is lost";
}

std::optional<LogTailDamage> check_log_tail(const std::filesystem::path& file) {
  std::ifstream in(file, std::ios::binary);
  if (!in) return std::nullopt;
  const std::vector<unsigned char> bytes{std::istreambuf_iterator<char>(in),
                                         std::istreambuf_iterator<char>()};
  const std::size_t size = bytes.size();
  std::size_t pos = 0;
  std::size_t whole = 0;  // end of the last whole batch (a FULL record or a FIRST..LAST run)
  bool in_batch = false;
  std::string reason;
  while (pos < size) {
    const std::size_t left_in_block = BLOCK - pos % BLOCK;
    if (left_in_block < HEADER) {  // block trailer: zero padding
      pos += left_in_block;
      continue;
    }
    if (size - pos < HEADER) {
      reason = "a record header is cut short after " + std::to_string(size - pos) + " bytes";
      break;
    }
    const std::size_t length = bytes[pos + 4] | (static_cast<std::size_t>(bytes[pos + 5]) << 8);
    const std::uint8_t type = bytes[pos + 6];
    if (type == ZERO && length == 0) {  // preallocated zeros: the writer never got here
      if (!all_zero(bytes, pos)) reason = "zero-type record followed by data";
      break;
    }
    if (HEADER + length > left_in_block || type > LAST) {
      reason = "a record header is not valid (type " + std::to_string(type) + ", length " +
               std::to_string(length) + ")";
      break;
    }
    if (pos + HEADER + length > size) {
      reason = "a record of " + std::to_string(length) + " bytes is cut short after " +
               std::to_string(size - pos - HEADER) + " bytes";
      break;
    }
    pos += HEADER + length;
    if (type == FULL || type == LAST) {
      whole = pos;
      in_batch = false;
    } else {
      in_batch = true;
    }
  }
  if (reason.empty() && in_batch) reason = "a batch split over blocks has no last fragment";
  if (reason.empty()) return std::nullopt;
  // Zero padding after the last whole batch carries nothing.
  if (whole < size && all_zero(bytes, whole)) return std::nullopt;
  return LogTailDamage{file, size - whole, reason};
}

std::optional<LogTailDamage> check_store_log(const std::filesystem::path& dir) {
  std::error_code ec;
  std::filesystem::path newest;
  std::uint64_t newest_number = 0;
  for (const auto& entry : std::filesystem::directory_iterator(dir, ec)) {
    const std::filesystem::path& p = entry.path();
    const std::string stem = p.stem().string();
    if (p.extension() != ".log" || stem.empty() || stem.size() > 19 ||
        !std::all_of(stem.begin(), stem.end(), [](char c) { return c >= '0' && c <= '9'; })) {
      continue;
    }
    // LevelDB names logs NNNNNN.log with a growing number: the newest has the greatest.
    const std::uint64_t number = std::stoull(stem);
    if (newest.empty() || number > newest_number) {
      newest = p;
      newest_number = number;
    }
  }
  if (newest.empty()) return std::nullopt;
  return check_log_tail(newest);
}

}  // namespace orthoflow::learning
