// LessonHistory: newest first, bounded (the oldest lesson goes), drop by label, exact values, and
// no undo past a lesson it could not keep.
#include "graphs/services/lesson_history.hpp"

#include <gtest/gtest.h>

#include <string>
#include <vector>

namespace orthoflow::graphs {
namespace {

std::vector<float> values_of(const LessonHistory& h) {
  LessonHistory::Lesson l;
  if (!h.newest(l)) return {};
  return {l.values.begin(), l.values.end()};
}
std::string label_of(const LessonHistory& h) {
  LessonHistory::Lesson l;
  return h.newest(l) ? std::string(l.label) : std::string("<none>");
}

TEST(LessonHistory, NewestComesBackFirstWithItsExactValues) {
  LessonHistory h(4, 6);
  LessonHistory::Lesson l;
  EXPECT_FALSE(h.newest(l));
  h.pop();  // no-op when empty
  h.push("cup", std::vector<float>{1, 2, 3});
  h.push("plate", std::vector<float>{4, 5, 6, 7, 8, 9});
  EXPECT_EQ(h.size(), 2U);
  EXPECT_EQ(label_of(h), "plate");
  EXPECT_EQ(values_of(h), (std::vector<float>{4, 5, 6, 7, 8, 9}));
  h.pop();
  EXPECT_EQ(label_of(h), "cup");
  EXPECT_EQ(values_of(h), (std::vector<float>{1, 2, 3}));
  h.pop();
  EXPECT_FALSE(h.newest(l));
}

TEST(LessonHistory, FullHistoryDropsTheOldest) {
  LessonHistory h(3, 2);
  for (int k = 0; k < 5; ++k) {
    h.push("l" + std::to_string(k), std::vector<float>{static_cast<float>(k), -1.0F});
  }
  ASSERT_EQ(h.size(), 3U);
  for (int k = 4; k >= 2; --k) {
    EXPECT_EQ(label_of(h), "l" + std::to_string(k));
    EXPECT_EQ(values_of(h), (std::vector<float>{static_cast<float>(k), -1.0F}));
    h.pop();
  }
  EXPECT_EQ(h.size(), 0U);
}

TEST(LessonHistory, DropRemovesEveryLessonOfALabelAndKeepsTheOrder) {
  LessonHistory h(8, 1);
  for (const char* label : {"a", "b", "a", "c", "a"}) h.push(label, std::vector<float>{1.0F});
  h.drop("a");
  ASSERT_EQ(h.size(), 2U);
  EXPECT_EQ(label_of(h), "c");
  h.pop();
  EXPECT_EQ(label_of(h), "b");
  h.drop("zzz");
  EXPECT_EQ(h.size(), 1U);
}

TEST(LessonHistory, ALessonTooLargeToKeepEndsTheUndoChain) {
  LessonHistory h(4, 2);
  h.push("a", std::vector<float>{1, 2});
  h.push("empty", std::vector<float>{});  // ignored
  EXPECT_EQ(label_of(h), "a");
  h.push("big", std::vector<float>{1, 2, 3});
  EXPECT_EQ(h.size(), 0U);  // undo must not skip "big" and take back "a"
}

}  // namespace
}  // namespace orthoflow::graphs
