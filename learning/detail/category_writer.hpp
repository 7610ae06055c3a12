#pragma once
/// @file
/// @brief The copy-on-write writer scaffold both learners share. A snapshot holds shared pointers
/// to immutable categories; every write takes the learner's writer lock, copies the pointer list,
/// replaces, adds or removes one entry and publishes the snapshot @p finish builds from the new
/// list, so readers (ask) never lock and never see a half-made change. Internal to learning/.
#include <algorithm>
#include <mutex>
#include <string_view>
#include <utility>
#include <vector>

#include "learning/learner.hpp"

namespace orthoflow::learning {

/// @brief The entry of @p categories whose label is @p label, or end().
template <class Ptr>
[[nodiscard]] auto find_label(std::vector<Ptr>& categories, std::string_view label) {
  return std::find_if(categories.begin(), categories.end(),
                      [&](const Ptr& c) { return c->label.view() == label; });
}

/// @brief Teach: replaces the category named @p label with make(existing, id), or adds
/// make(nullptr, new id).
/// @p finish(categories, generation, next_id) builds the snapshot to publish. @return the
/// category's id.
template <class Cell, class Make, class Finish>
CategoryId upsert_category(std::mutex& writer, Cell& cell, std::string_view label, Make&& make,
                           Finish&& finish) {
  const std::lock_guard lock(writer);
  const auto& cur = cell.writer_view();
  auto next = cur.categories;
  CategoryId next_id = cur.next_id;
  const auto it = find_label(next, label);
  const bool fresh = it == next.end();
  auto updated = make(fresh ? nullptr : it->get(), fresh ? next_id++ : (*it)->id);
  const CategoryId id = updated->id;
  if (fresh) {
    next.push_back(std::move(updated));
  } else {
    *it = std::move(updated);
  }
  cell.publish(finish(std::move(next), cur.generation + 1, next_id));
  return id;
}

/// @brief Forget: removes the category named @p label (UNKNOWN_LABEL, nothing published, if none
/// is).
template <class Cell, class Finish>
Result<void, LearnError> erase_category(std::mutex& writer, Cell& cell, std::string_view label,
                                        Finish&& finish) {
  const std::lock_guard lock(writer);
  const auto& cur = cell.writer_view();
  auto next = cur.categories;
  const auto it = find_label(next, label);
  if (it == next.end()) { return err(LearnError::UNKNOWN_LABEL); }
  next.erase(it);
  cell.publish(finish(std::move(next), cur.generation + 1, cur.next_id));
  return {};
}

/// @brief Retract: replaces the category named @p label with make(existing), a
/// Result<Ptr, LearnError>; a null Ptr removes the category. UNKNOWN_LABEL, or make's error, and
/// nothing is published.
template <class Cell, class Make, class Finish>
Result<void, LearnError> shrink_category(std::mutex& writer, Cell& cell, std::string_view label,
                                         Make&& make, Finish&& finish) {
  const std::lock_guard lock(writer);
  const auto& cur = cell.writer_view();
  auto next = cur.categories;
  const auto it = find_label(next, label);
  if (it == next.end()) { return err(LearnError::UNKNOWN_LABEL); }
  auto shrunk = make(**it);
  if (!shrunk) { return err(shrunk.error()); }
  if (*shrunk == nullptr) {
    next.erase(it);
  } else {
    *it = std::move(*shrunk);
  }
  cell.publish(finish(std::move(next), cur.generation + 1, cur.next_id));
  return {};
}

/// @brief Restore: publishes @p categories (sorted by id here) in place of everything the learner
/// held.
template <class Cell, class Ptr, class Finish>
void replace_categories(std::mutex& writer, Cell& cell, std::vector<Ptr> categories,
                        CategoryId next_id, Finish&& finish) {
  std::sort(categories.begin(), categories.end(),
            [](const Ptr& a, const Ptr& b) { return a->id < b->id; });
  const std::lock_guard lock(writer);
  cell.publish(finish(std::move(categories), cell.writer_view().generation + 1, next_id));
}

}  // namespace orthoflow::learning
