#include "apps/option_checks.hpp"

#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <string>

namespace orthoflow::apps {

namespace {

bool numeric(const std::string& type) {
  return type.rfind("INT", 0) == 0 || type.rfind("UINT", 0) == 0 || type.rfind("FLOAT", 0) == 0;
}

// The whole text must be a number (strtod accepts "nan" and "inf": they are refused below).
std::string finite_non_negative(const std::string& text) {
  errno = 0;
  char* end = nullptr;
  const double v = std::strtod(text.c_str(), &end);
  if (text.empty() || end != text.c_str() + text.size()) return "'" + text + "' is not a number";
  if (!std::isfinite(v) || errno == ERANGE) return "'" + text + "' is not a finite number";
  if (v < 0.0) return "'" + text + "' is negative";
  return {};
}

}  // namespace

void check_numeric_options(CLI::App& app) {
  const CLI::Validator rule(finite_non_negative, "FINITE >= 0", "finite, non-negative");
  for (CLI::Option* option : app.get_options()) {
    if (numeric(option->get_type_name())) option->check(rule);
  }
  for (CLI::App* sub : app.get_subcommands({})) check_numeric_options(*sub);
}

}  // namespace orthoflow::apps
