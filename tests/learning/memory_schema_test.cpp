// The perceptual memory records its descriptor specification (kernels/descriptor_spec.hpp): a store
// written before the specification existed (schema key without "descriptor") opens unchanged, a
// store of an unknown descriptor kind is refused, and a mismatch names both specifications.
#include <gtest/gtest.h>
#include <leveldb/db.h>

#include <memory>
#include <string>
#include <vector>

#include "memory_test_util.hpp"

namespace orthoflow::learning {
namespace {

using test::fresh_dir;
using test::make_view;
using test::small_config;
constexpr std::size_t LENGTH = 75;

std::string schema_of(const std::filesystem::path& dir) {
  leveldb::DB* raw = nullptr;
  EXPECT_TRUE(leveldb::DB::Open(leveldb::Options(), dir.string(), &raw).ok());
  std::unique_ptr<leveldb::DB> db(raw);
  std::string value;
  EXPECT_TRUE(db->Get(leveldb::ReadOptions(), "s", &value).ok());
  return value;
}

void set_schema(const std::filesystem::path& dir, const std::string& json) {
  leveldb::DB* raw = nullptr;
  ASSERT_TRUE(leveldb::DB::Open(leveldb::Options(), dir.string(), &raw).ok());
  std::unique_ptr<leveldb::DB> db(raw);
  ASSERT_TRUE(db->Put(leveldb::WriteOptions(), "s", json).ok());
}

TEST(MemorySchema, NewStoresRecordTheDescriptorKind) {
  const auto dir = fresh_dir();
  {
    auto m = PerceptualMemory::open(dir, small_config());
    ASSERT_TRUE(m);
  }
  const std::string schema = schema_of(dir);
  EXPECT_NE(schema.find("\"descriptor\":\"good\""), std::string::npos) << schema;
  EXPECT_NE(schema.find("\"bins\":5"), std::string::npos) << schema;
}

TEST(MemorySchema, AStoreOfThePreviousReleaseOpensUnchanged) {
  const auto dir = fresh_dir();
  {
    auto m = PerceptualMemory::open(dir, small_config());
    ASSERT_TRUE(m);
    ASSERT_TRUE(m->teach("mug", std::vector{make_view(LENGTH, 1, 1), make_view(LENGTH, 1, 2)}));
  }
  // Exactly what the previous release wrote: no "descriptor" field.
  set_schema(dir, R"({"bins":5,"mode":"invariant","schema":1,"threshold":0.014999999664723873})");
  auto reopened = PerceptualMemory::open(dir, small_config());
  ASSERT_TRUE(reopened) << reopened.error().to_string();
  EXPECT_EQ(reopened->stats().views, 2U);
  AskScratch scratch;
  EXPECT_EQ(reopened->learner().ask(make_view(LENGTH, 1, 3).descriptor, scratch).label.view(),
            "mug");
}

TEST(MemorySchema, AnUnknownDescriptorKindIsRefusedUntouched) {
  const auto dir = fresh_dir();
  {
    auto m = PerceptualMemory::open(dir, small_config());
    ASSERT_TRUE(m);
  }
  const std::string foreign =
      R"({"bins":5,"descriptor":"spin_images","mode":"invariant","schema":1,"threshold":0.015})";
  set_schema(dir, foreign);
  auto refused = PerceptualMemory::open(dir, small_config());
  ASSERT_FALSE(refused);
  EXPECT_EQ(refused.error().code, MemoryError::Code::CORRUPT);
  EXPECT_NE(refused.error().message.find("spin_images"), std::string::npos)
      << refused.error().message;
  EXPECT_EQ(schema_of(dir), foreign);
}

TEST(MemorySchema, AMismatchNamesBothSpecifications) {
  const auto dir = fresh_dir();
  {
    auto m = PerceptualMemory::open(dir, small_config());
    ASSERT_TRUE(m);
  }
  MemoryConfig other = small_config();
  other.descriptor = kernels::DescriptorSpec::make_good(7, kernels::GoodMode::REFERENCE);
  auto refused = PerceptualMemory::open(dir, other);
  ASSERT_FALSE(refused);
  EXPECT_EQ(refused.error().code, MemoryError::Code::PARAMS_MISMATCH);
  EXPECT_NE(refused.error().message.find("good bins=5 mode=invariant"), std::string::npos)
      << refused.error().message;
  EXPECT_NE(refused.error().message.find("good bins=7 mode=reference"), std::string::npos)
      << refused.error().message;
}

}  // namespace
}  // namespace orthoflow::learning
