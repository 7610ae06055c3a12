#pragma once
/// @file
/// @brief How the kernels' error messages print their numbers: counts as integers ("12 points",
/// never "12.000000 points") and other values as a user would type them (%g: "0.005", "-1").
/// Allocates: for the errors' to_string(), off the frame path.
#include <cstdint>
#include <cstdio>
#include <string>

namespace orthoflow::kernels::detail {

/// @brief A value as %g prints it ("0.005", "-1", "nan", "1e+30").
inline std::string value_text(double value) {
  char text[32];
  std::snprintf(text, sizeof text, "%g", value);
  return text;
}

/// @brief A count carried in an error's double value, as an integer (anything that is not a
/// whole count in range, as value_text).
inline std::string count_text(double value) {
  const bool whole = value >= 0.0 && value < 1.8e19 &&
                     static_cast<double>(static_cast<std::uint64_t>(value)) == value;
  return whole ? std::to_string(static_cast<std::uint64_t>(value)) : value_text(value);
}

}  // namespace orthoflow::kernels::detail
