#pragma once
/// @file
/// @brief Small helpers the text parts of file formats share: a line cursor that knows its line
/// number and byte offset, whitespace tokenising, and strict number parsing.
#include <charconv>
#include <cstddef>
#include <cstdint>
#include <span>
#include <string_view>

namespace orthoflow::formats {

/// @brief Walks a byte buffer line by line ('\n', with an optional '\r' stripped).
class LineCursor {
 public:
  explicit LineCursor(std::span<const char> bytes, std::size_t offset = 0,
                      std::size_t first_line = 1) noexcept
      : bytes_(bytes), offset_(offset), next_line_(first_line) {}
  /// @brief Gets the next line; false at the end of the buffer.
  bool next(std::string_view& line) noexcept;
  /// @brief 1-based number of the line next() returned last.
  [[nodiscard]] std::size_t line_number() const noexcept { return next_line_ - 1; }
  /// @brief Byte offset just past the line next() returned last (where the following data starts).
  [[nodiscard]] std::size_t offset() const noexcept { return offset_; }

 private:
  std::span<const char> bytes_;
  std::size_t offset_;
  std::size_t next_line_;
};

/// @brief Splits at spaces and tabs; returns the number of tokens written (at most out.size()),
/// and sets @p more when tokens were left over.
std::size_t split_ws(std::string_view line, std::span<std::string_view> out, bool& more) noexcept;

/// @brief Parses the whole token as T (integers: decimal; floats: also "nan", "inf"). False
/// otherwise.
template <class T>
bool parse_number(std::string_view token, T& value) noexcept {
  if (token.empty()) { return false; }
  if (token.front() == '+') { token.remove_prefix(1); }
  const auto [end, ec] = std::from_chars(token.data(), token.data() + token.size(), value);
  return ec == std::errc() && end == token.data() + token.size();
}

}  // namespace orthoflow::formats
