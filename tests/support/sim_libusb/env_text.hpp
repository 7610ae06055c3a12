#pragma once
// (internal) The text helpers the ORTHOFLOW_SIM_KINECT / ORTHOFLOW_SIM_JACO parsers share.
#include <charconv>
#include <string_view>
#include <system_error>
#include <vector>

namespace orthoflow::sim_libusb::env_text {

inline std::string_view trim(std::string_view s) noexcept {
  while (!s.empty() && (s.front() == ' ' || s.front() == '\t')) s.remove_prefix(1);
  while (!s.empty() && (s.back() == ' ' || s.back() == '\t')) s.remove_suffix(1);
  return s;
}

inline std::vector<std::string_view> split(std::string_view s, char separator) {
  std::vector<std::string_view> parts;
  for (;;) {
    const std::size_t at = s.find(separator);
    parts.push_back(trim(s.substr(0, at)));
    if (at == std::string_view::npos) return parts;
    s.remove_prefix(at + 1);
  }
}

template <class T>
bool parse_number(std::string_view text, T& out) noexcept {
  const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), out);
  return ec == std::errc{} && end == text.data() + text.size() && !text.empty();
}

inline bool parse_rate(std::string_view text, double& out) noexcept {
  return parse_number(text, out) && out >= 0.0 && out <= 1.0;
}

}  // namespace orthoflow::sim_libusb::env_text
