#include "formats/text_scan.hpp"

namespace orthoflow::formats {

bool LineCursor::next(std::string_view& line) noexcept {
  if (offset_ >= bytes_.size()) { return false; }
  std::size_t end = offset_;
  while (end < bytes_.size() && bytes_[end] != '\n') { ++end; }
  line = std::string_view(bytes_.data() + offset_, end - offset_);
  if (!line.empty() && line.back() == '\r') { line.remove_suffix(1); }
  offset_ = (end < bytes_.size()) ? end + 1 : end;
  ++next_line_;
  return true;
}

std::size_t split_ws(std::string_view line, std::span<std::string_view> out, bool& more) noexcept {
  std::size_t n = 0;
  std::size_t i = 0;
  more = false;
  while (i < line.size()) {
    while (i < line.size() && (line[i] == ' ' || line[i] == '\t')) { ++i; }
    if (i >= line.size()) { break; }
    std::size_t j = i;
    while (j < line.size() && line[j] != ' ' && line[j] != '\t') { ++j; }
    if (n == out.size()) {
      more = true;
      break;
    }
    out[n++] = line.substr(i, j - i);
    i = j;
  }
  return n;
}

}  // namespace orthoflow::formats
