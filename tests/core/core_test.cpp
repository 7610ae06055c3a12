// core/: the one random generator (pinned sequence, ranges), fixed-capacity text, the
// single-producer ring (wrap-around, all-or-nothing pushes, in-place claim, two threads) and the
// spin lock.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <numeric>
#include <string>
#include <thread>
#include <vector>

#include "core/fixed_text.hpp"
#include "core/label_text.hpp"
#include "core/rng.hpp"
#include "core/spin_lock.hpp"
#include "core/spsc_ring.hpp"

namespace orthoflow::core {
namespace {

TEST(Rng, SameSeedSameSequenceDifferentSeedDifferent) {
  Rng a(42), b(42), c(43);
  bool differs = false;
  for (int i = 0; i < 1000; ++i) {
    const std::uint64_t x = a.next();
    EXPECT_EQ(x, b.next());
    differs = differs || x != c.next();
  }
  EXPECT_TRUE(differs);
}

TEST(Rng, FirstValuesArePinned) {
  // xoshiro256** seeded by SplitMix64 from 0: the values every platform must produce (x86-64,
  // aarch64).
  Rng r(0);
  const std::uint64_t first = r.next(), second = r.next();
  Rng again(0);
  EXPECT_EQ(again.next(), first);
  EXPECT_EQ(again.next(), second);
  EXPECT_EQ(first, 0x99EC5F36CB75F2B4ULL);
  EXPECT_EQ(second, 0xBF6E1F784956452AULL);
}

TEST(Rng, BelowStaysInRangeForSmallAndHugeBounds) {
  Rng r(7);
  for (const std::uint64_t n :
       {1ULL, 2ULL, 3ULL, 7ULL, 1000ULL, (1ULL << 32) + 1, (1ULL << 63) + 5, ~0ULL}) {
    for (int i = 0; i < 2000; ++i) EXPECT_LT(r.below(n), n);
  }
  std::vector<int> counts(6, 0);
  for (int i = 0; i < 60000; ++i) ++counts[r.below(6)];
  for (const int c : counts) EXPECT_NEAR(c, 10000, 500);  // unbiased within 5 sigma
}

TEST(Rng, UniformAndNormalMoments) {
  Rng r(9);
  double sum = 0.0, sq = 0.0, usum = 0.0;
  const int n = 100000;
  for (int i = 0; i < n; ++i) {
    const double u = r.uniform();
    ASSERT_GE(u, 0.0);
    ASSERT_LT(u, 1.0);
    usum += u;
    const double g = r.normal();
    sum += g;
    sq += g * g;
  }
  EXPECT_NEAR(usum / n, 0.5, 0.01);
  EXPECT_NEAR(sum / n, 0.0, 0.02);
  EXPECT_NEAR(sq / n, 1.0, 0.03);
}

TEST(FixedText, TruncatesTerminatesAndCompares) {
  Text t;
  EXPECT_TRUE(t.empty());
  EXPECT_EQ(t.view(), "");
  t.assign("mug");
  EXPECT_EQ(t.view(), "mug");
  t.assign(std::string(200, 'x'));
  EXPECT_EQ(t.view().size(), TEXT_MAX_BYTES);
  t.assign("bowl");  // shorter after longer: no leftover bytes
  EXPECT_EQ(t.view(), "bowl");
  EXPECT_EQ(Text::from("bowl"), t);
  EXPECT_FALSE(Text::from("bow") == t);
  const std::string with_zero("ab\0cd", 5);
  EXPECT_EQ(Text::from(with_zero).view(), "ab");  // as view() reads it
  static_assert(std::is_trivially_copyable_v<Text>);
  Text checked;
  EXPECT_TRUE(checked.try_assign(std::string(TEXT_MAX_BYTES, 'y')));
  EXPECT_EQ(checked.view().size(), TEXT_MAX_BYTES);
  EXPECT_FALSE(checked.try_assign(std::string(TEXT_MAX_BYTES + 1, 'y')));  // would be cut: refused
  EXPECT_TRUE(checked.empty());
  EXPECT_FALSE(checked.try_assign(with_zero));
}

TEST(FixedText, ElidedKeepsTheStartAndTheEnd) {
  Text t;
  t.assign_elided("short");  // fits: as assign()
  EXPECT_EQ(t.view(), "short");
  const std::string fits(TEXT_MAX_BYTES, 'f');
  t.assign_elided(fits);
  EXPECT_EQ(t.view(), fits);
  // One byte too long: the middle gives way to "...", the start and the end stay.
  const std::string path = "/a/long/checkout/" + std::string(60, 'd') + "/b.pcd: line 1: bad";
  t.assign_elided(path);
  ASSERT_EQ(t.view().size(), TEXT_MAX_BYTES);
  EXPECT_EQ(t.view().substr(0, 17), "/a/long/checkout/");
  EXPECT_NE(t.view().find("..."), std::string_view::npos);
  EXPECT_TRUE(t.view().ends_with("/b.pcd: line 1: bad"));
  t.assign_elided("x");  // shorter after longer: no leftover bytes
  EXPECT_EQ(t.view(), "x");
  FixedText<9> small;
  small.assign_elided("0123456789");
  EXPECT_EQ(small.view(), "012...789");
}

TEST(LabelText, OneRuleForEveryLabel) {
  EXPECT_EQ(check_label("mug"), LabelProblem::NONE);
  EXPECT_EQ(check_label("\xF0\x9F\x8D\xB5 cup"), LabelProblem::NONE);  // a 4-byte code point
  EXPECT_EQ(check_label(std::string(TEXT_MAX_BYTES, 'a')), LabelProblem::NONE);
  EXPECT_EQ(check_label(""), LabelProblem::EMPTY);
  EXPECT_EQ(check_label(std::string(TEXT_MAX_BYTES + 1, 'a')), LabelProblem::TOO_LONG);
  EXPECT_EQ(check_label("a\nb"), LabelProblem::CONTROL_CHARACTER);
  EXPECT_EQ(check_label(std::string("a\0b", 3)), LabelProblem::CONTROL_CHARACTER);
  EXPECT_EQ(check_label("\xC2\x9F"), LabelProblem::CONTROL_CHARACTER);  // C1
  EXPECT_EQ(check_label("\x80"), LabelProblem::NOT_UTF8);               // stray continuation
  EXPECT_EQ(check_label("\xE0\x80\xAF"), LabelProblem::NOT_UTF8);       // overlong
  EXPECT_EQ(check_label("\xF4\x90\x80\x80"), LabelProblem::NOT_UTF8);   // beyond U+10FFFF
  EXPECT_EQ(check_label("\xE2\x82"), LabelProblem::NOT_UTF8);           // cut short
}

// Look-alike labels (issue 52, item 7): each of these displays as "mug" (or "café") beside the
// plain one, so each is refused; a person's decomposed text is composed by normalized_label.
TEST(LabelText, LabelsThatDisplayAlikeAreOneLabel) {
  for (const char* hidden :
       {"\u200B", "\u200C", "\u200D", "\u200E", "\u200F",     "\u202A", "\u202E",
        "\u2066", "\u2069", "\u2060", "\uFEFF", "\u00AD",     "\u034F", "\uFE0F",
        "\u180E", "\u2028", "\u2029", "\u061C", "\U000E0041", "\u3164"}) {
    SCOPED_TRACE(hidden);
    EXPECT_EQ(check_label(std::string("mug") + hidden), LabelProblem::INVISIBLE_CHARACTER);
    EXPECT_EQ(check_label(std::string("m") + hidden + "ug"), LabelProblem::INVISIBLE_CHARACTER);
    auto typed = normalized_label(std::string("m") + hidden + "ug");
    ASSERT_FALSE(typed.has_value());
    EXPECT_EQ(typed.error(), LabelProblem::INVISIBLE_CHARACTER);
  }
  const std::string composed = "caf\u00E9";     // é as one code point
  const std::string decomposed = "cafe\u0301";  // e and a combining acute accent
  EXPECT_EQ(check_label(composed), LabelProblem::NONE);
  EXPECT_EQ(check_label(decomposed), LabelProblem::NOT_NFC);
  auto typed = normalized_label(decomposed);
  ASSERT_TRUE(typed.has_value());
  EXPECT_EQ(*typed, composed);
  // Combining marks in non-canonical order (dot below after acute) are not NFC either.
  EXPECT_EQ(check_label("q\u0301\u0323"), LabelProblem::NOT_NFC);
  EXPECT_EQ(check_label("q\u0323\u0301"), LabelProblem::NONE);
  EXPECT_EQ(check_label("\u212B"), LabelProblem::NOT_NFC);  // ANGSTROM SIGN: NFC is U+00C5
  EXPECT_EQ(*normalized_label("\u212B"), "\u00C5");
  // What stays allowed: scripts, emoji without selectors, inner spaces, Hangul, Arabic, Devanagari.
  for (const char* fine : {"\u00E9clair", "\U0001F375 cup", "tea cup", "\uD55C\uAE00",
                           "\u0643\u0648\u0628", "\u0915\u092A", "\u30DE\u30B0", "Stra\u00DFe"}) {
    SCOPED_TRACE(fine);
    EXPECT_EQ(check_label(fine), LabelProblem::NONE);
    EXPECT_EQ(*normalized_label(fine), fine);
  }
  EXPECT_EQ(normalized_label("\xC3").error(), LabelProblem::NOT_UTF8);
  EXPECT_EQ(normalized_label("").error(), LabelProblem::EMPTY);
  EXPECT_EQ(normalized_label(std::string(TEXT_MAX_BYTES + 1, 'a')).error(), LabelProblem::TOO_LONG);
}

TEST(SpscRing, FullEmptyAndAllOrNothing) {
  SpscRing<int> ring(4);
  int out = 0;
  EXPECT_FALSE(ring.try_pop(out));
  const std::vector<int> three{1, 2, 3};
  EXPECT_TRUE(ring.try_push_all(three));
  EXPECT_FALSE(ring.try_push_all(three));  // 3 more do not fit in 1: none goes in
  EXPECT_EQ(ring.size(), 3U);
  EXPECT_TRUE(ring.try_push(4));
  EXPECT_FALSE(ring.try_push(5));
  EXPECT_EQ(ring.claim(), nullptr);
  for (int want = 1; want <= 4; ++want) {
    ASSERT_TRUE(ring.try_pop(out));
    EXPECT_EQ(out, want);
  }
  EXPECT_EQ(ring.size(), 0U);
}

TEST(SpscRing, ReadableSplitsAtTheWrapAndClaimFillsInPlace) {
  SpscRing<int> ring(5);
  for (int i = 0; i < 4; ++i) ASSERT_TRUE(ring.try_push(i));
  ring.release(3);  // tail at 3
  for (int i = 4; i < 8; ++i) ASSERT_TRUE(ring.try_push(i));
  const auto [first, second] = ring.readable();
  EXPECT_EQ(std::vector<int>(first.begin(), first.end()), (std::vector<int>{3, 4}));
  EXPECT_EQ(std::vector<int>(second.begin(), second.end()), (std::vector<int>{5, 6, 7}));
  ring.clear();
  EXPECT_EQ(ring.size(), 0U);
  int* slot = ring.claim();
  ASSERT_NE(slot, nullptr);
  *slot = 42;
  EXPECT_EQ(ring.peek(), nullptr);  // not visible before publish()
  ring.publish();
  ASSERT_NE(ring.peek(), nullptr);
  EXPECT_EQ(*ring.peek(), 42);
}

TEST(SpscRing, SlotOfNamesTheSlotEachEndHolds) {
  SpscRing<int> ring(3);
  for (std::size_t n = 0; n < 7; ++n) {  // past two wraps: the n-th claim holds slot n % 3
    int* claimed = ring.claim();
    ASSERT_NE(claimed, nullptr);
    EXPECT_EQ(ring.slot_of(claimed), n % 3);
    ring.publish();
    EXPECT_EQ(ring.slot_of(ring.peek()), n % 3);  // the consumer sees the same slot
    ring.release(1);
  }
}

TEST(SpscRing, TwoThreadsKeepOrderAndLoseNothing) {
  SpscRing<std::uint64_t> ring(64);
  constexpr std::uint64_t N = 200000;
  std::thread producer([&] {
    for (std::uint64_t i = 0; i < N;) {
      if (ring.try_push(i)) ++i;
    }
  });
  std::uint64_t expected = 0, value = 0;
  while (expected < N) {
    if (ring.try_pop(value)) {
      ASSERT_EQ(value, expected);
      ++expected;
    }
  }
  producer.join();
}

TEST(SpinLock, ExcludesAndTryLockFailsWhenHeld) {
  SpinLock lock;
  lock.lock();
  EXPECT_FALSE(lock.try_lock());
  lock.unlock();
  EXPECT_TRUE(lock.try_lock());
  lock.unlock();
  std::uint64_t counter = 0;
  auto work = [&] {
    for (int i = 0; i < 100000; ++i) {
      const std::lock_guard guard(lock);
      ++counter;
    }
  };
  std::thread a(work), b(work);
  a.join();
  b.join();
  EXPECT_EQ(counter, 200000U);
}

}  // namespace
}  // namespace orthoflow::core
