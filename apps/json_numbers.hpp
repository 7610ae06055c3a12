#pragma once
/// @file
/// @brief JSON number helpers shared by the CLI commands.
#include <array>
#include <charconv>

#include <nlohmann/json.hpp>

namespace orthoflow::apps {

/// @brief The floats as JSON numbers whose text is each float's shortest round-trip text
/// (0.1F prints as 0.1, not 0.100000001).
template <class Floats>
nlohmann::json floats_json(const Floats& values) {
  nlohmann::json out = nlohmann::json::array();
  for (const float v : values) {
    std::array<char, 32> text{};
    const auto written = std::to_chars(text.data(), text.data() + text.size(), v);
    double shortest = 0.0;
    std::from_chars(text.data(), written.ptr, shortest);
    out.push_back(shortest);
  }
  return out;
}

}  // namespace orthoflow::apps
