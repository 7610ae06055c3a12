#pragma once
/// @file
/// @brief LessonHistory: the recent teaches and corrects the learning service can take back
/// (undo), newest last, each with its label and exactly the descriptors it taught, so that an undo
/// hands the learner and the perceptual memory what they were given (learning::Learner::retract).
/// Fixed capacity, sized at construction: push, pop and drop never allocate.
#include <cstdint>
#include <span>
#include <string_view>
#include <vector>

#include "core/fixed_text.hpp"

namespace orthoflow::graphs {

/// @brief Lessons kept for undo (the oldest is dropped when a new one arrives beyond it).
inline constexpr std::size_t MAX_UNDO_LESSONS = 16;

/// @note Thread-compatible: one thread (the recognise node's) uses it.
class LessonHistory {
 public:
  /// @brief Room for @p lessons lessons of at most @p max_values descriptor values each.
  LessonHistory(std::size_t lessons, std::size_t max_values);

  /// @brief One kept lesson (views into the history: valid until the next push, pop or drop).
  struct Lesson {
    std::string_view label;
    std::span<const float> values;  ///< the taught views, row-major
  };

  /// @brief Keeps a lesson; the oldest goes when full. A lesson of more than max_values values
  /// could not be undone exactly: it empties the history (undo must never skip the newest lesson
  /// and take back an older one instead). An empty lesson is ignored.
  void push(std::string_view label, std::span<const float> values) noexcept;
  /// @brief The newest lesson; false when there is none.
  [[nodiscard]] bool newest(Lesson& out) const noexcept;
  /// @brief Removes the newest lesson (no-op when empty).
  void pop() noexcept;
  /// @brief Removes every lesson of @p label (after a forget: its views are gone).
  void drop(std::string_view label) noexcept;
  [[nodiscard]] std::size_t size() const noexcept { return count_; }

 private:
  struct Entry {
    core::Text label;
    std::size_t values = 0;
  };
  void move_entry(std::size_t from, std::size_t to) noexcept;
  std::vector<Entry> entries_;
  std::vector<float> values_;  // entry k at [k * max_values_, ...)
  std::size_t max_values_;
  std::size_t count_ = 0;
};

}  // namespace orthoflow::graphs
