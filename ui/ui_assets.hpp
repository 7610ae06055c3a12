#pragma once
/// @file
/// @brief The web view's files, compiled into the binary (ui/assets/, embedded by
/// ui/embed_assets.cmake). The server serves only these: a path is looked up by exact match in the
/// table, so no request reaches the file system and nothing can escape a root.
#include <cstddef>
#include <span>
#include <string_view>

namespace orthoflow::ui {

/// @brief One embedded file.
struct Asset {
  const char* path;          ///< "/", "/index.html", "/app.js", ...
  const char* content_type;  ///< e.g. "text/html; charset=utf-8"
  const unsigned char* bytes;
  std::size_t size;
  [[nodiscard]] std::string_view text() const noexcept {
    return {reinterpret_cast<const char*>(bytes), size};
  }
};

/// @brief Every embedded file (generated at build time).
[[nodiscard]] std::span<const Asset> embedded_assets() noexcept;

/// @brief The asset at exactly @p path, or nullptr. Thread-safe; never allocates.
[[nodiscard]] const Asset* find_asset(std::string_view path) noexcept;

}  // namespace orthoflow::ui
