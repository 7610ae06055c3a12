#include "memory_pool/block_pool.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <cstring>
#include <new>
#include <set>
#include <thread>
#include <vector>

#include "memory_pool/aligned_resource.hpp"

namespace orthoflow::memory_pool {
namespace {

struct ExternalMemory {
  explicit ExternalMemory(std::size_t n)
      : data(static_cast<std::byte*>(::operator new (n, std::align_val_t{CACHE_LINE_BYTES}))),
        size(n) {}
  ~ExternalMemory() { ::operator delete (data, std::align_val_t{CACHE_LINE_BYTES}); }
  ExternalMemory(const ExternalMemory&) = delete;
  ExternalMemory& operator=(const ExternalMemory&) = delete;
  std::span<std::byte> span() { return {data, size}; }
  std::byte* data;
  std::size_t size;
};

TEST(BlockPool, RequiredBytesCoversControlAndAlignedBlocks) {
  EXPECT_EQ(required_bytes({100, 4, "p"}), 64u + 4u * 128u);
  EXPECT_EQ(required_bytes({64, 1, "p"}), 64u + 64u);
  EXPECT_EQ(required_bytes({0, 4, "p"}), 0u);
  EXPECT_EQ(required_bytes({64, 0, "p"}), 0u);
  EXPECT_EQ(required_bytes({MAX_BLOCK_BYTES + 1, 1, "p"}), 0u);
}

TEST(BlockPool, SitsOnExternalMemoryAndBlocksLieInside) {
  const PoolConfig config{100, 4, "ext"};
  ExternalMemory memory(required_bytes(config));
  auto pool_result = BlockPool::create(config, memory.span());
  ASSERT_TRUE(pool_result);
  auto& pool = **pool_result;
  std::vector<BlockHandle> handles;
  for (int i = 0; i < 4; ++i) {
    auto block_result = pool.acquire("test", 100);
    ASSERT_TRUE(block_result);
    const auto bytes = block_result->bytes();
    EXPECT_EQ(bytes.size(), 100u);
    EXPECT_GE(bytes.data(), memory.data);
    EXPECT_LE(bytes.data() + bytes.size(), memory.data + memory.size);
    EXPECT_EQ(reinterpret_cast<std::uintptr_t>(bytes.data()) % CACHE_LINE_BYTES, 0u);
    std::memset(bytes.data(), i, bytes.size());
    handles.push_back(std::move(*block_result));
  }
  for (int i = 0; i < 4; ++i)
    EXPECT_EQ(static_cast<int>(handles[static_cast<std::size_t>(i)].bytes()[99]), i);
}

TEST(BlockPool, ExhaustionNamesRequesterAndSize) {
  auto pool_result = BlockPool::create_owned({256, 2, "frames"});
  ASSERT_TRUE(pool_result);
  auto a = (*pool_result)->acquire("camera", 10);
  auto b = (*pool_result)->acquire("camera", 10);
  ASSERT_TRUE(a && b);
  auto c = (*pool_result)->acquire("segmenter", 200);
  ASSERT_FALSE(c);
  EXPECT_EQ(c.error().code, PoolError::Code::EXHAUSTED);
  const std::string message = to_string(c.error());
  EXPECT_NE(message.find("segmenter"), std::string::npos) << message;
  EXPECT_NE(message.find("200 bytes"), std::string::npos) << message;
  EXPECT_NE(message.find("frames"), std::string::npos) << message;
}

TEST(BlockPool, EveryErrorCodeIsReachable) {
  auto too_large = BlockPool::create_owned({256, 1, "p"});
  ASSERT_TRUE(too_large);
  auto big = (*too_large)->acquire("reader", 257);
  ASSERT_FALSE(big);
  EXPECT_EQ(big.error().code, PoolError::Code::TOO_LARGE);
  EXPECT_NE(to_string(big.error()).find("257"), std::string::npos);

  auto bad = BlockPool::create_owned({0, 1, "p"});
  ASSERT_FALSE(bad);
  EXPECT_EQ(bad.error().code, PoolError::Code::BAD_CONFIG);

  ExternalMemory memory(4096);
  auto small = BlockPool::create({1024, 8, "p"}, memory.span());
  ASSERT_FALSE(small);
  EXPECT_EQ(small.error().code, PoolError::Code::MEMORY_TOO_SMALL);
  EXPECT_NE(to_string(small.error()).find("4096"), std::string::npos);

  auto misaligned = BlockPool::create({64, 2, "p"}, memory.span().subspan(8, 1024));
  ASSERT_FALSE(misaligned);
  EXPECT_EQ(misaligned.error().code, PoolError::Code::MEMORY_MISALIGNED);
  EXPECT_EQ(to_string(PoolError::Code::MEMORY_MISALIGNED), "MEMORY_MISALIGNED");

  // Within every field's limit, far beyond any machine: refused as an error, never std::bad_alloc.
  auto huge = BlockPool::create_owned({MAX_BLOCK_BYTES, MAX_BLOCKS, "p"});
  ASSERT_FALSE(huge);
  EXPECT_EQ(huge.error().code, PoolError::Code::OUT_OF_MEMORY);
  EXPECT_NE(to_string(huge.error()).find("refused"), std::string::npos) << to_string(huge.error());
}

TEST(BlockPool, LastHandleReturnsTheBlock) {
  auto pool_result = BlockPool::create_owned({64, 1, "p"});
  auto& pool = **pool_result;
  auto first = pool.acquire("a", 1);
  ASSERT_TRUE(first);
  BlockHandle copy = *first;
  EXPECT_EQ(copy.use_count(), 2u);
  BlockHandle moved = std::move(copy);
  EXPECT_FALSE(copy);  // NOLINT(bugprone-use-after-move): moved-from state is specified
  EXPECT_EQ(moved.use_count(), 2u);
  first->reset();
  EXPECT_EQ(pool.free_count(), 0u);
  EXPECT_FALSE(pool.acquire("b", 1));
  BlockHandle assigned;
  assigned = moved;
  moved = BlockHandle{};
  EXPECT_EQ(pool.free_count(), 0u);
  assigned.reset();
  EXPECT_EQ(pool.free_count(), 1u);
  EXPECT_TRUE(pool.acquire("c", 1));
}

TEST(BlockPool, ConcurrentAcquireReleaseNeverDuplicatesABlock) {
  constexpr std::size_t BLOCKS = 16;
  auto pool_result = BlockPool::create_owned({64, BLOCKS, "mt"});
  auto& pool = **pool_result;
  std::vector<std::atomic<int>> owners(BLOCKS);
  std::atomic<bool> duplicate{false};
  std::atomic<long> acquired{0};
  auto worker = [&] {
    std::vector<BlockHandle> held;
    for (int i = 0; i < 20000; ++i) {
      auto block_result = pool.acquire("worker", 8);
      if (block_result) {
        if (owners[block_result->index()].fetch_add(1) != 0) duplicate = true;
        held.push_back(std::move(*block_result));
        acquired.fetch_add(1, std::memory_order_relaxed);
      }
      if (held.size() > 2 || (!block_result && !held.empty())) {
        owners[held.front().index()].fetch_sub(1);
        BlockHandle shared = held.front();  // a copy on another "holder" must not free it early
        held.erase(held.begin());
      }
    }
    for (auto& h : held) owners[h.index()].fetch_sub(1);
  };
  std::vector<std::thread> threads;
  for (int t = 0; t < 4; ++t) threads.emplace_back(worker);
  for (auto& t : threads) t.join();
  EXPECT_FALSE(duplicate.load());
  EXPECT_GT(acquired.load(), 1000);
  EXPECT_EQ(pool.free_count(), BLOCKS);
  std::set<std::uint32_t> distinct;
  std::vector<BlockHandle> all;
  for (std::size_t i = 0; i < BLOCKS; ++i) {
    auto block_result = pool.acquire("final", 1);
    ASSERT_TRUE(block_result);
    distinct.insert(block_result->index());
    all.push_back(std::move(*block_result));
  }
  EXPECT_EQ(distinct.size(), BLOCKS);
}

}  // namespace
}  // namespace orthoflow::memory_pool
