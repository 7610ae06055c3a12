#pragma once
/// @file
/// @brief The largest input orthoflow reads from a file or a stream: 1 GiB, or the value of the
/// ORTHOFLOW_MAX_INPUT_BYTES environment variable when it holds a positive whole number. Every
/// reader (PCD, PLY, memory imports) stops there, so an endless input such as /dev/zero is an
/// error, never an allocation without bound.
#include <cstddef>
#include <cstdlib>

namespace orthoflow::core {

/// @brief The limit in bytes. Read once from the environment; thread-safe.
[[nodiscard]] inline std::size_t max_input_bytes() noexcept {
  static const std::size_t limit = [] {
    const char* text = std::getenv("ORTHOFLOW_MAX_INPUT_BYTES");
    char* end = nullptr;
    const unsigned long long v = text != nullptr ? std::strtoull(text, &end, 10) : 0;
    return text != nullptr && *text != '\0' && *end == '\0' && v > 0 ? static_cast<std::size_t>(v)
                                                                     : std::size_t{1} << 30;
  }();
  return limit;
}

}  // namespace orthoflow::core
