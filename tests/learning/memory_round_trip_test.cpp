// Export and import are a proven round trip (issue 16, data loss 2): everything a store can hold
// (any finite descriptor value from denormals to the float limit, negative zero, 64-bit track ids
// and stamps at their limits, UTF-8 labels of every length, gaps left by forget, either learner)
// comes back bit for bit, and a second export of the copy is byte-identical to the first. What a
// store cannot hold is refused at teach time, before anything is written.
#include <gtest/gtest.h>

#include <bit>
#include <cmath>
#include <fstream>
#include <limits>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "memory_test_util.hpp"

namespace orthoflow::learning {
namespace {

using test::fresh_dir;
using test::make_view;
using test::small_config;
using Code = MemoryError::Code;
constexpr std::size_t LENGTH = 75;

std::string file_text(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

// A random finite non-negative descriptor value: zeros, denormals, ordinary histogram values and
// values near the float limit, drawn as raw bit patterns so every exponent is visited.
float random_value(std::mt19937_64& rng) {
  switch (rng() % 4) {
    case 0:
      return 0.0F;
    case 1:
      return std::bit_cast<float>(static_cast<std::uint32_t>(rng() % 0x7F800000U));  // finite >= 0
    case 2:
      return std::numeric_limits<float>::denorm_min() * static_cast<float>(1 + rng() % 1000);
    default:
      return static_cast<float>(rng() % 1000000) / 1e6F;
  }
}

float random_signed(std::mt19937_64& rng) {
  const float v = random_value(rng);
  return rng() % 2 == 0 ? v : -v;  // -0.0 included
}

ViewRecord random_view(std::mt19937_64& rng) {
  ViewRecord v;
  v.descriptor.resize(LENGTH);
  for (float& d : v.descriptor) d = random_value(rng);
  v.descriptor[rng() % LENGTH] = 0.5F;  // never all zeros
  for (float& f : v.frame) f = random_signed(rng);
  for (float& b : v.bbox) b = random_signed(rng);
  const std::uint64_t ids[] = {0, 1, std::numeric_limits<std::uint64_t>::max(), rng()};
  v.track_id = ids[rng() % 4];
  const std::int64_t stamps[] = {0, -1, std::numeric_limits<std::int64_t>::min(),
                                 std::numeric_limits<std::int64_t>::max(),
                                 static_cast<std::int64_t>(rng())};
  v.stamp_ns = stamps[rng() % 5];
  return v;
}

void expect_same_view(const ViewRecord& a, const ViewRecord& b, const std::string& where) {
  ASSERT_EQ(a.descriptor.size(), b.descriptor.size()) << where;
  for (std::size_t i = 0; i < a.descriptor.size(); ++i) {
    EXPECT_EQ(std::bit_cast<std::uint32_t>(a.descriptor[i]),
              std::bit_cast<std::uint32_t>(b.descriptor[i]))
        << where << " descriptor " << i;
  }
  for (std::size_t i = 0; i < 16; ++i) {
    EXPECT_EQ(std::bit_cast<std::uint32_t>(a.frame[i]), std::bit_cast<std::uint32_t>(b.frame[i]))
        << where << " frame " << i;
  }
  for (std::size_t i = 0; i < 3; ++i) {
    EXPECT_EQ(std::bit_cast<std::uint32_t>(a.bbox[i]), std::bit_cast<std::uint32_t>(b.bbox[i]))
        << where << " bbox " << i;
  }
  EXPECT_EQ(a.track_id, b.track_id) << where;
  EXPECT_EQ(a.stamp_ns, b.stamp_ns) << where;
}

void expect_same_store(const PerceptualMemory& a, const PerceptualMemory& b) {
  const auto la = a.list();
  const auto lb = b.list();
  ASSERT_EQ(la.size(), lb.size());
  for (std::size_t k = 0; k < la.size(); ++k) {
    EXPECT_EQ(la[k].label, lb[k].label);
    ASSERT_EQ(la[k].views, lb[k].views) << la[k].label;
    const auto va = a.views_of(la[k].id);
    const auto vb = b.views_of(lb[k].id);
    ASSERT_TRUE(va && vb);
    for (std::size_t v = 0; v < va->size(); ++v) {
      expect_same_view((*va)[v], (*vb)[v], la[k].label + " view " + std::to_string(v));
    }
  }
}

TEST(MemoryRoundTrip, EverythingAStoreHoldsComesBackBitForBit) {
  const std::string labels[] = {"mug",
                                "tasse à café",
                                "杯子",
                                "a",
                                std::string(63, 'x'),
                                "emoji 🍵",
                                "spaces  inside",
                                "quote \" and \\ backslash"};
  for (const LearnerKind kind : {LearnerKind::INSTANCE, LearnerKind::BAYES}) {
    const std::string tag = kind == LearnerKind::INSTANCE ? "_instance" : "_bayes";
    std::mt19937_64 rng(16);
    auto original = PerceptualMemory::open(fresh_dir(tag), small_config(kind), OpenMode::CREATE);
    ASSERT_TRUE(original);
    for (const std::string& label : labels) {
      std::vector<ViewRecord> views;
      for (std::size_t v = 0, n = 1 + rng() % 5; v < n; ++v) views.push_back(random_view(rng));
      ASSERT_TRUE(original->teach(label, views)) << label;
    }
    ASSERT_TRUE(original->correct("mug", random_view(rng)));
    ASSERT_TRUE(original->forget("a"));  // a gap in the ids
    const std::string first = fresh_dir(tag + "_first").string() + ".jsonl";
    ASSERT_TRUE(original->export_to(first));

    auto copy =
        PerceptualMemory::open(fresh_dir(tag + "_copy"), small_config(kind), OpenMode::CREATE);
    ASSERT_TRUE(copy);
    const auto imported = copy->import_from(first);
    ASSERT_TRUE(imported) << imported.error().to_string();
    expect_same_store(*original, *copy);
    const std::string second = fresh_dir(tag + "_second").string() + ".jsonl";
    ASSERT_TRUE(copy->export_to(second));
    EXPECT_EQ(file_text(first), file_text(second));
    EXPECT_EQ(copy->stats().learner.categories, original->stats().learner.categories);
  }
}

TEST(MemoryRoundTrip, WhatAStoreCannotHoldIsRefusedAtTeachTime) {
  auto m = PerceptualMemory::open(fresh_dir(), small_config(), OpenMode::CREATE);
  ASSERT_TRUE(m);
  const float nan = std::numeric_limits<float>::quiet_NaN();
  const float inf = std::numeric_limits<float>::infinity();
  struct Case {
    const char* why;
    ViewRecord view;
  };
  std::vector<Case> cases;
  cases.push_back({"object frame is not finite", make_view(LENGTH, 1, 1)});
  cases.back().view.frame[3] = nan;
  cases.push_back({"bounding box is not finite", make_view(LENGTH, 1, 2)});
  cases.back().view.bbox[0] = inf;
  cases.push_back({"descriptor is all zeros", make_view(LENGTH, 1, 3)});
  cases.back().view.descriptor.assign(LENGTH, 0.0F);
  for (const Case& c : cases) {
    // The bad view second: nothing of the call, not even the good first view, is written.
    const auto r = m->teach("mug", std::vector{make_view(LENGTH, 2, 9), c.view});
    ASSERT_FALSE(r) << c.why;
    EXPECT_EQ(r.error().code, Code::REJECTED);
    EXPECT_NE(r.error().message.find("view 1"), std::string::npos) << r.error().message;
    EXPECT_NE(r.error().message.find(c.why), std::string::npos) << r.error().message;
    const auto corrected = m->correct("mug", c.view);
    EXPECT_FALSE(corrected) << c.why;
  }
  EXPECT_TRUE(m->list().empty());
  EXPECT_EQ(m->stats().writes, 0U);
}

TEST(MemoryRoundTrip, AnImportRestoresTheEmptyViewsOfEarlierStores) {
  // Stores of earlier releases took all-zero views; their exports must still import.
  auto m = PerceptualMemory::open(fresh_dir(), small_config(), OpenMode::CREATE);
  ASSERT_TRUE(m);
  ASSERT_TRUE(m->teach("mug", std::vector{make_view(LENGTH, 1, 1)}));
  const std::string file = fresh_dir("_export").string() + ".jsonl";
  ASSERT_TRUE(m->export_to(file));
  // Rewrite the view's descriptor as an earlier release would have written an empty view.
  std::string text = file_text(file);
  const auto at = text.find("\"descriptor\":[");
  ASSERT_NE(at, std::string::npos);
  const auto end = text.find(']', at);
  std::string zeros = "\"descriptor\":[";
  for (std::size_t i = 0; i < LENGTH; ++i) zeros += i ? ",0.0" : "0.0";
  text.replace(at, end - at, zeros);
  std::ofstream(file, std::ios::binary | std::ios::trunc) << text;
  auto copy = PerceptualMemory::open(fresh_dir("_copy"), small_config(), OpenMode::CREATE);
  ASSERT_TRUE(copy);
  const auto imported = copy->import_from(file);
  ASSERT_TRUE(imported) << imported.error().to_string();
  EXPECT_EQ(*imported, 1U);
}

}  // namespace
}  // namespace orthoflow::learning
