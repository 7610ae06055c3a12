#pragma once
/// @file
/// @brief ParamMap: the scalar parameters of one node as written in the graph file, with typed,
/// range-checked getters whose errors name the key and the line.
#include <cstdint>
#include <string>
#include <vector>

#include "core/result.hpp"

namespace orthoflow::engine {

/// @brief Key/value scalars of one node, remembering where each was written.
/// @note Used only while a graph is built (start-up), never on the frame path.
class ParamMap {
 public:
  struct Entry {
    std::string key;
    std::string value;
    int line = 0;  ///< 1-based line in the graph file (0 if built in code)
  };
  /// @brief Adds a parameter. @pre key not already present.
  void set(std::string key, std::string value, int line = 0);
  [[nodiscard]] bool has(const std::string& key) const;
  /// @brief Integer in [min, max]; `fallback` if absent. Error: "parameter 'k' (line L): ...".
  [[nodiscard]] Result<std::int64_t, std::string> integer(const std::string& key,
                                                          std::int64_t fallback, std::int64_t min,
                                                          std::int64_t max) const;
  /// @brief Finite real number in [min, max]; `fallback` if absent.
  [[nodiscard]] Result<double, std::string> number(const std::string& key, double fallback,
                                                   double min, double max) const;
  /// @brief Free text (a path, a topic); `fallback` if absent. Error if present but empty.
  [[nodiscard]] Result<std::string, std::string> text(const std::string& key,
                                                      const std::string& fallback) const;
  /// @brief Sets `key` to `value`, replacing an existing entry (command-line overrides of a graph
  /// file).
  void assign(const std::string& key, std::string value);
  /// @brief One of `choices`; `fallback` if absent.
  [[nodiscard]] Result<std::string, std::string> choice(
      const std::string& key, const std::string& fallback,
      const std::vector<std::string>& choices) const;
  /// @brief Marks every key in `known` as used; returns an error naming the first unknown key.
  [[nodiscard]] Result<void, std::string> only(const std::vector<std::string>& known) const;
  [[nodiscard]] const std::vector<Entry>& entries() const noexcept { return entries_; }

 private:
  [[nodiscard]] const Entry* find(const std::string& key) const;
  std::vector<Entry> entries_;
};

}  // namespace orthoflow::engine
