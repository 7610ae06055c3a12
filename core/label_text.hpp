#pragma once
/// @file
/// @brief The one rule for a category label, whatever brings it in (CLI, learning channel, import,
/// the web view and DDS commands): 1 to TEXT_MAX_BYTES bytes of valid UTF-8 in Unicode
/// normalization form C, without control characters (C0, DEL, C1: a newline or a tab would break
/// `memory list`, a NUL cut the label short) and without invisible or direction-control characters
/// (format characters such as U+200B zero width space or U+202E right-to-left override, default
/// ignorables such as U+00AD soft hyphen or U+FE0F variation selector, line and paragraph
/// separators): two labels that display alike are then one label. Entry points where a person
/// types (the CLI, the web view) pass the text through normalized_label first, so a decomposed "é"
/// becomes the composed one; a peer that sends a label not in NFC is refused.
#include <cstdint>
#include <string>
#include <string_view>

#include "core/fixed_text.hpp"
#include "core/result.hpp"

namespace orthoflow::core {

/// @brief What is wrong with a label.
enum class LabelProblem : std::uint8_t {
  NONE,
  EMPTY,     ///< ""
  TOO_LONG,  ///< more than TEXT_MAX_BYTES bytes
  NOT_UTF8,  ///< not valid UTF-8 (stray continuation byte, overlong form, surrogate, > U+10FFFF)
  CONTROL_CHARACTER,    ///< a control character (U+0000-U+001F, U+007F-U+009F)
  INVISIBLE_CHARACTER,  ///< a format (Cf), default-ignorable, line or paragraph separator character
  NOT_NFC,              ///< not in Unicode normalization form C (a decomposed "é")
};

/// @brief Checks @p label against the rule. Never allocates; linear in the label's length.
[[nodiscard]] LabelProblem check_label(std::string_view label) noexcept;

/// @brief @p text in normalization form C, then checked: what a person typed, as a label.
[[nodiscard]] Result<std::string, LabelProblem> normalized_label(std::string_view text);

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
    case LabelProblem::INVISIBLE_CHARACTER:
      return "label holds an invisible or direction-control character";
    case LabelProblem::NOT_NFC:
      return "label is not in Unicode normalization form C";
  }
  return "label is invalid";
}

}  // namespace orthoflow::core
