#include "graphs/services/lesson_history.hpp"

#include <algorithm>

namespace orthoflow::graphs {

LessonHistory::LessonHistory(std::size_t lessons, std::size_t max_values)
    : entries_(std::max<std::size_t>(lessons, 1)),
      values_(entries_.size() * max_values),
      max_values_(max_values) {}

void LessonHistory::move_entry(std::size_t from, std::size_t to) noexcept {
  entries_[to] = entries_[from];
  const auto at = [this](std::size_t k) {
    return values_.begin() + static_cast<std::ptrdiff_t>(k * max_values_);
  };
  std::copy_n(at(from), entries_[from].values, at(to));
}

void LessonHistory::push(std::string_view label, std::span<const float> values) noexcept {
  if (values.size() > max_values_) {
    count_ = 0;  // the newest lesson cannot be taken back, so neither can any before it
    return;
  }
  if (values.empty()) return;
  if (count_ == entries_.size()) {
    for (std::size_t k = 1; k < count_; ++k) move_entry(k, k - 1);
    --count_;
  }
  Entry& e = entries_[count_];
  e.label.assign(label);
  e.values = values.size();
  std::copy(values.begin(), values.end(),
            values_.begin() + static_cast<std::ptrdiff_t>(count_ * max_values_));
  ++count_;
}

bool LessonHistory::newest(Lesson& out) const noexcept {
  if (count_ == 0) return false;
  const Entry& e = entries_[count_ - 1];
  out.label = e.label.view();
  out.values = std::span<const float>(values_).subspan((count_ - 1) * max_values_, e.values);
  return true;
}

void LessonHistory::pop() noexcept {
  if (count_ > 0) --count_;
}

void LessonHistory::drop(std::string_view label) noexcept {
  std::size_t kept = 0;
  for (std::size_t k = 0; k < count_; ++k) {
    if (entries_[k].label.view() == label) continue;
    if (kept != k) move_entry(k, kept);
    ++kept;
  }
  count_ = kept;
}

}  // namespace orthoflow::graphs
