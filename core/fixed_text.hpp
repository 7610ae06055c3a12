#pragma once
/// @file
/// @brief Fixed-capacity text: category labels, node names and messages that travel on the frame
/// path, in pool blocks, in IPC payloads and in learner snapshots. Copying never allocates; the
/// bytes are inline and always zero-terminated, so the type is trivially copyable and has the same
/// layout on every platform (a char array of capacity + 1).
#include <algorithm>
#include <array>
#include <cstddef>
#include <cstring>
#include <string_view>

namespace orthoflow::core {

/// @brief Up to @p CAPACITY bytes of text stored inline with a terminating zero.
/// @note A value type; not synchronised (copy it across threads).
template <std::size_t CAPACITY>
struct FixedText {
  std::array<char, CAPACITY + 1> chars{};

  /// @brief The longest text it keeps, in bytes.
  static constexpr std::size_t capacity() noexcept { return CAPACITY; }
  /// @brief The text up to its terminating zero ("" when empty). Never allocates.
  [[nodiscard]] std::string_view view() const noexcept {
    // chars[CAPACITY] is always zero (assign writes at most CAPACITY bytes), so strnlen stays in
    // bounds.
    return {chars.data(), ::strnlen(chars.data(), chars.size())};
  }
  /// @brief Stores @p s, truncated to CAPACITY bytes (and at an embedded zero, as view() reads it).
  void assign(std::string_view s) noexcept {
    const std::size_t n = std::min(s.size(), CAPACITY);
    if (n > 0) std::memcpy(chars.data(), s.data(), n);  // an empty view may hold a null pointer
    std::fill(chars.begin() + static_cast<std::ptrdiff_t>(n), chars.end(), '\0');
  }
  /// @brief Stores @p s; one longer than CAPACITY keeps its start and its end with "..." between
  /// them, so that a message's subject (a path's file name) and its reason both survive. For
  /// messages, never labels. Never allocates.
  void assign_elided(std::string_view s) noexcept {
    static_assert(CAPACITY >= 9, "room for a start, \"...\" and an end");
    if (s.size() <= CAPACITY) {
      assign(s);
      return;
    }
    const std::size_t tail = (CAPACITY - 3) / 2;
    const std::size_t head = CAPACITY - 3 - tail;
    std::memcpy(chars.data(), s.data(), head);
    std::memcpy(chars.data() + head, "...", 3);
    std::memcpy(chars.data() + head + 3, s.data() + (s.size() - tail), tail);
    chars[CAPACITY] = '\0';
  }
  /// @brief Stores @p s only if it fits whole (at most CAPACITY bytes, no embedded zero); otherwise
  /// leaves the text empty. @return whether it was stored: what a caller checks before it sends a
  /// label that must not be cut short.
  [[nodiscard]] bool try_assign(std::string_view s) noexcept {
    if (s.size() > CAPACITY || s.find('\0') != std::string_view::npos) {
      assign({});
      return false;
    }
    assign(s);
    return true;
  }
  /// @brief A text holding @p s (truncated as assign()).
  [[nodiscard]] static FixedText from(std::string_view s) noexcept {
    FixedText t;
    t.assign(s);
    return t;
  }
  [[nodiscard]] bool empty() const noexcept { return chars[0] == '\0'; }
  [[nodiscard]] bool operator==(const FixedText& other) const noexcept {
    return view() == other.view();
  }
};

/// @brief Longest label or name in bytes (category names, node names in errors).
inline constexpr std::size_t TEXT_MAX_BYTES = 63;
/// @brief The text every room shares: 63 bytes and a zero, 64 bytes in all.
using Text = FixedText<TEXT_MAX_BYTES>;
static_assert(sizeof(Text) == 64);

}  // namespace orthoflow::core
