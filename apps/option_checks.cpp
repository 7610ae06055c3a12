#include "apps/option_checks.hpp"

#include <cerrno>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <string>

#include "core/label_text.hpp"

namespace orthoflow::apps {

namespace {

bool integral(const std::string& type) {
  return type.rfind("INT", 0) == 0 || type.rfind("UINT", 0) == 0;
}

bool numeric(const std::string& type) { return integral(type) || type.rfind("FLOAT", 0) == 0; }

// The whole text must be a number (strtod accepts "nan" and "inf": they are refused below).
std::string finite_non_negative(const std::string& text) {
  errno = 0;
  char* end = nullptr;
  const double v = std::strtod(text.c_str(), &end);
  const std::string quoted = "'" + text + "'";
  if (text.empty() || end != text.c_str() + text.size()) return quoted + " is not a number";
  if (!std::isfinite(v) || errno == ERANGE) return quoted + " is not a finite number";
  if (v < 0.0 || text[0] == '-') return quoted + " is negative (expected 0 or more)";
  return {};
}

// Counts, frames, ports, timeouts: digits only, within int64 (CLI11 would say "Could not convert"
// for "1.5" and saturate "99999999999999999999" to the type's maximum without a word).
std::string whole_non_negative(const std::string& text) {
  if (std::string problem = finite_non_negative(text); !problem.empty()) return problem;
  const std::string quoted = "'" + text + "'";
  const std::size_t digits = text[0] == '+' ? 1 : 0;
  if (text.size() == digits || text.find_first_not_of("0123456789", digits) != std::string::npos)
    return quoted + " is not a whole number";
  errno = 0;
  const unsigned long long v = std::strtoull(text.c_str(), nullptr, 10);
  if (errno == ERANGE || v > static_cast<unsigned long long>(INT64_MAX))
    return quoted + " is too large (at most " + std::to_string(INT64_MAX) + ")";
  return {};
}

}  // namespace

void check_numeric_options(CLI::App& app) {
  const CLI::Validator number(finite_non_negative, "FINITE >= 0", "finite, non-negative");
  const CLI::Validator whole(whole_non_negative, "WHOLE >= 0", "whole, non-negative");
  for (CLI::Option* option : app.get_options()) {
    const std::string type = option->get_type_name();
    if (integral(type)) {
      option->check(whole);
    } else if (numeric(type)) {
      option->check(number);
    }
  }
  for (CLI::App* sub : app.get_subcommands({})) check_numeric_options(*sub);
}

CLI::Validator composed_label() {
  return CLI::Validator(
      [](std::string& text) {
        if (auto composed = core::normalized_label(text)) text = std::move(*composed);
        return std::string();
      },
      "", "composed label");
}

}  // namespace orthoflow::apps
