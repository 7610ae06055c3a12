#include "engine/params.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>

namespace orthoflow::engine {

namespace {
std::string where(const ParamMap::Entry& entry) {
  return "parameter '" + entry.key + "'" +
         (entry.line > 0 ? " (line " + std::to_string(entry.line) + ")" : "");
}
}  // namespace

void ParamMap::set(std::string key, std::string value, int line) {
  entries_.push_back({std::move(key), std::move(value), line});
}

bool ParamMap::has(const std::string& key) const { return find(key) != nullptr; }

const ParamMap::Entry* ParamMap::find(const std::string& key) const {
  const auto it =
      std::find_if(entries_.begin(), entries_.end(), [&](const Entry& e) { return e.key == key; });
  return it == entries_.end() ? nullptr : &*it;
}

Result<std::int64_t, std::string> ParamMap::integer(const std::string& key, std::int64_t fallback,
                                                    std::int64_t min, std::int64_t max) const {
  const Entry* entry = find(key);
  if (entry == nullptr) return fallback;
  std::int64_t value = 0;
  const char* first = entry->value.data();
  const char* last = first + entry->value.size();
  const auto [ptr, ec] = std::from_chars(first, last, value);
  if (ec != std::errc{} || ptr != last)
    return err(where(*entry) + ": '" + entry->value + "' is not an integer");
  if (value < min || value > max) {
    return err(where(*entry) + ": " + entry->value + " is outside [" + std::to_string(min) + ", " +
               std::to_string(max) + "]");
  }
  return value;
}

Result<double, std::string> ParamMap::number(const std::string& key, double fallback, double min,
                                             double max) const {
  const Entry* entry = find(key);
  if (entry == nullptr) return fallback;
  double value = 0.0;
  const char* first = entry->value.data();
  const char* last = first + entry->value.size();
  const auto [ptr, ec] = std::from_chars(first, last, value);
  if (ec != std::errc{} || ptr != last || !std::isfinite(value)) {
    return err(where(*entry) + ": '" + entry->value + "' is not a finite number");
  }
  if (value < min || value > max) {
    return err(where(*entry) + ": " + entry->value + " is outside [" + std::to_string(min) + ", " +
               std::to_string(max) + "]");
  }
  return value;
}

Result<std::string, std::string> ParamMap::text(const std::string& key,
                                                const std::string& fallback) const {
  const Entry* entry = find(key);
  if (entry == nullptr) return fallback;
  if (entry->value.empty()) return err(where(*entry) + ": must not be empty");
  return entry->value;
}

void ParamMap::assign(const std::string& key, std::string value) {
  for (auto& entry : entries_) {
    if (entry.key == key) {
      entry.value = std::move(value);
      entry.line = 0;
      return;
    }
  }
  entries_.push_back({key, std::move(value), 0});
}

Result<std::string, std::string> ParamMap::choice(const std::string& key,
                                                  const std::string& fallback,
                                                  const std::vector<std::string>& choices) const {
  const Entry* entry = find(key);
  if (entry == nullptr) return fallback;
  if (std::find(choices.begin(), choices.end(), entry->value) != choices.end()) return entry->value;
  std::string list;
  for (const auto& c : choices) list += (list.empty() ? "" : ", ") + c;
  return err(where(*entry) + ": '" + entry->value + "' is not one of {" + list + "}");
}

Result<void, std::string> ParamMap::only(const std::vector<std::string>& known) const {
  for (const auto& entry : entries_) {
    if (std::find(known.begin(), known.end(), entry.key) == known.end()) {
      return err(where(entry) + ": unknown parameter for this node kind");
    }
  }
  return {};
}

}  // namespace orthoflow::engine
