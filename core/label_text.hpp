#pragma once
/// @file
/// @brief The one rule for a category label, whatever brings it in (CLI, learning channel, import,
/// the coming web UI and DDS commands): 1 to TEXT_MAX_BYTES bytes of valid UTF-8 without control
/// characters (C0, DEL, C1: a newline or a tab would break `memory list`, a NUL cut the label
/// short).
#include <cstdint>
#include <string_view>

#include "core/fixed_text.hpp"

namespace orthoflow::core {

/// @brief What is wrong with a label.
enum class LabelProblem : std::uint8_t {
  NONE,
  EMPTY,     ///< ""
  TOO_LONG,  ///< more than TEXT_MAX_BYTES bytes
  NOT_UTF8,  ///< not valid UTF-8 (stray continuation byte, overlong form, surrogate, > U+10FFFF)
  CONTROL_CHARACTER,  ///< a control character (U+0000-U+001F, U+007F-U+009F)
};

/// @brief Checks @p label against the rule. Never allocates; linear in the label's length.
[[nodiscard]] constexpr LabelProblem check_label(std::string_view label) noexcept {
  if (label.empty()) return LabelProblem::EMPTY;
  if (label.size() > TEXT_MAX_BYTES) return LabelProblem::TOO_LONG;
  for (std::size_t i = 0; i < label.size();) {
    const auto b = static_cast<unsigned char>(label[i]);
    const std::size_t n = b < 0x80             ? 1
                          : (b & 0xE0) == 0xC0 ? 2
                          : (b & 0xF0) == 0xE0 ? 3
                          : (b & 0xF8) == 0xF0 ? 4
                                               : 0;
    if (n == 0 || i + n > label.size()) return LabelProblem::NOT_UTF8;
    std::uint32_t cp = n == 1 ? b : n == 2 ? (b & 0x1FU) : n == 3 ? (b & 0x0FU) : (b & 0x07U);
    for (std::size_t k = 1; k < n; ++k) {
      const auto c = static_cast<unsigned char>(label[i + k]);
      if ((c & 0xC0) != 0x80) return LabelProblem::NOT_UTF8;
      cp = (cp << 6) | (c & 0x3FU);
    }
    const std::uint32_t least[5] = {0, 0, 0x80, 0x800, 0x10000};
    if (cp < least[n] || cp > 0x10FFFF || (cp >= 0xD800 && cp <= 0xDFFF))
      return LabelProblem::NOT_UTF8;
    if (cp < 0x20 || (cp >= 0x7F && cp <= 0x9F)) return LabelProblem::CONTROL_CHARACTER;
    i += n;
  }
  return LabelProblem::NONE;
}

/// @brief A sentence for @p problem, e.g. "label holds a control character".
[[nodiscard]] constexpr std::string_view to_string(LabelProblem problem) noexcept {
  switch (problem) {
    case LabelProblem::NONE:
      return "label is fine";
    case LabelProblem::EMPTY:
      return "label is empty";
    case LabelProblem::TOO_LONG:
      return "label is longer than 63 bytes";
    case LabelProblem::NOT_UTF8:
      return "label is not valid UTF-8";
    case LabelProblem::CONTROL_CHARACTER:
      return "label holds a control character";
  }
  return "label is invalid";
}

}  // namespace orthoflow::core
