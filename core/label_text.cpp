#include "core/label_text.hpp"

#include <utf8proc.h>

#include <array>
#include <cstdlib>
#include <memory>

namespace orthoflow::core {
namespace {

// A label's code points: at most one per byte. Canonical decomposition (NFD) of one code point is
// at most 4 code points in Unicode 15 (utf8proc 2.8's data); 8 per byte leaves room for any
// version.
constexpr std::size_t MAX_CODE_POINTS = TEXT_MAX_BYTES;
constexpr std::size_t MAX_DECOMPOSED = 8 * TEXT_MAX_BYTES;
constexpr auto NFC_OPTIONS = static_cast<utf8proc_option_t>(UTF8PROC_STABLE | UTF8PROC_COMPOSE);

/// Decodes @p label (at most TEXT_MAX_BYTES bytes) into @p out; NONE or the first problem.
LabelProblem decode(std::string_view label, std::array<utf8proc_int32_t, MAX_CODE_POINTS>& out,
                    std::size_t& count) noexcept {
  count = 0;
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
    constexpr std::array<std::uint32_t, 5> least = {0, 0, 0x80, 0x800, 0x10000};
    if (cp < least[n] || cp > 0x10FFFF || (cp >= 0xD800 && cp <= 0xDFFF))
      return LabelProblem::NOT_UTF8;
    if (cp < 0x20 || (cp >= 0x7F && cp <= 0x9F)) return LabelProblem::CONTROL_CHARACTER;
    out[count++] = static_cast<utf8proc_int32_t>(cp);
    i += n;
  }
  return LabelProblem::NONE;
}

bool invisible(utf8proc_int32_t cp) noexcept {
  const utf8proc_property_t* p = utf8proc_get_property(cp);
  return p->ignorable != 0 || p->category == UTF8PROC_CATEGORY_CF ||
         p->category == UTF8PROC_CATEGORY_ZL || p->category == UTF8PROC_CATEGORY_ZP;
}

/// True when @p label (valid UTF-8 whose code points are @p cps) is its own NFC. utf8proc_decompose
/// decomposes and puts combining marks in canonical order into the caller's buffer (no allocation);
/// utf8proc_normalize_utf32 composes in place.
bool is_nfc(std::string_view label, const std::array<utf8proc_int32_t, MAX_CODE_POINTS>& cps,
            std::size_t count) noexcept {
  std::array<utf8proc_int32_t, MAX_DECOMPOSED> buffer{};
  const utf8proc_ssize_t n =
      utf8proc_decompose(reinterpret_cast<const utf8proc_uint8_t*>(label.data()),
                         static_cast<utf8proc_ssize_t>(label.size()), buffer.data(),
                         static_cast<utf8proc_ssize_t>(buffer.size()), NFC_OPTIONS);
  if (n < 0 || static_cast<std::size_t>(n) > buffer.size()) return false;
  const utf8proc_ssize_t composed = utf8proc_normalize_utf32(buffer.data(), n, NFC_OPTIONS);
  if (composed < 0 || static_cast<std::size_t>(composed) != count) return false;
  for (std::size_t i = 0; i < count; ++i)
    if (buffer[i] != cps[i]) return false;
  return true;
}

}  // namespace

LabelProblem check_label(std::string_view label) noexcept {
  if (label.empty()) return LabelProblem::EMPTY;
  if (label.size() > TEXT_MAX_BYTES) return LabelProblem::TOO_LONG;
  std::array<utf8proc_int32_t, MAX_CODE_POINTS> cps{};
  std::size_t count = 0;
  if (const LabelProblem p = decode(label, cps, count); p != LabelProblem::NONE) return p;
  for (std::size_t i = 0; i < count; ++i)
    if (invisible(cps[i])) return LabelProblem::INVISIBLE_CHARACTER;
  return is_nfc(label, cps, count) ? LabelProblem::NONE : LabelProblem::NOT_NFC;
}

Result<std::string, LabelProblem> normalized_label(std::string_view text) {
  if (text.empty()) return err(LabelProblem::EMPTY);
  if (text.size() > 4 * TEXT_MAX_BYTES) return err(LabelProblem::TOO_LONG);
  utf8proc_uint8_t* mapped = nullptr;
  const utf8proc_ssize_t n =
      utf8proc_map(reinterpret_cast<const utf8proc_uint8_t*>(text.data()),
                   static_cast<utf8proc_ssize_t>(text.size()), &mapped, NFC_OPTIONS);
  const std::unique_ptr<utf8proc_uint8_t, decltype(&std::free)> owned(mapped, &std::free);
  if (n < 0) {
    // utf8proc refuses invalid UTF-8 before NFC; the rule says which problem it is.
    const LabelProblem p = check_label(text);
    return err(p == LabelProblem::NONE ? LabelProblem::NOT_UTF8 : p);
  }
  std::string label(reinterpret_cast<const char*>(mapped), static_cast<std::size_t>(n));
  if (const LabelProblem p = check_label(label); p != LabelProblem::NONE) return err(p);
  return label;
}

}  // namespace orthoflow::core
