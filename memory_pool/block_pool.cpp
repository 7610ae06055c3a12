#include "memory_pool/block_pool.hpp"

#include <new>

#include "memory_pool/aligned_resource.hpp"

namespace orthoflow::memory_pool {

// Control words live in the caller's memory, ahead of the blocks, so that a pool placed in shared
// memory keeps all of its state there (iceoryx MemPool keeps its free list beside the chunks too).
struct BlockPool::Control {
  std::atomic<std::uint32_t> refs;
  std::atomic<std::uint32_t> next;  // free-list link: index + 1 of the next free block, 0 = end
};

namespace {

constexpr std::uint64_t INDEX_MASK = 0xFFFF'FFFFull;

constexpr std::size_t round_up(std::size_t value, std::size_t to) noexcept {
  return (value + to - 1) / to * to;
}

bool config_ok(const PoolConfig& config) noexcept {
  return config.block_bytes > 0 && config.block_bytes <= MAX_BLOCK_BYTES &&
         config.block_count > 0 && config.block_count <= MAX_BLOCKS;
}

std::size_t control_bytes(std::size_t count) noexcept {
  return round_up(count * sizeof(std::atomic<std::uint32_t>) * 2, CACHE_LINE_BYTES);
}

}  // namespace

std::string_view to_string(PoolError::Code code) noexcept {
  switch (code) {
    case PoolError::Code::EXHAUSTED:
      return "EXHAUSTED";
    case PoolError::Code::TOO_LARGE:
      return "TOO_LARGE";
    case PoolError::Code::BAD_CONFIG:
      return "BAD_CONFIG";
    case PoolError::Code::MEMORY_TOO_SMALL:
      return "MEMORY_TOO_SMALL";
    case PoolError::Code::MEMORY_MISALIGNED:
      return "MEMORY_MISALIGNED";
    case PoolError::Code::OUT_OF_MEMORY:
      return "OUT_OF_MEMORY";
  }
  return "UNKNOWN";
}

std::string to_string(const PoolError& error) {
  std::string text = "pool '" + std::string(error.pool) + "': ";
  const std::string who = "'" + std::string(error.requester) + "'";
  const std::string bytes = std::to_string(error.bytes);
  const std::string limit = std::to_string(error.limit);
  switch (error.code) {
    case PoolError::Code::EXHAUSTED:
      return text + "exhausted: " + who + " asked for " + bytes + " bytes but all " + limit +
             " blocks are in use";
    case PoolError::Code::TOO_LARGE:
      return text + who + " asked for " + bytes + " bytes, more than the block size of " + limit +
             " bytes";
    case PoolError::Code::BAD_CONFIG:
      return text + "bad configuration from " + who +
             ": block_bytes must be in [1, 2^30] and block_count in [1, 2^24]";
    case PoolError::Code::MEMORY_TOO_SMALL:
      return text + who + " provided " + bytes + " bytes of memory but the pool needs " + limit;
    case PoolError::Code::MEMORY_MISALIGNED:
      return text + who + " provided memory that is not 64-byte aligned";
    case PoolError::Code::OUT_OF_MEMORY:
      return text + "the system refused " + bytes + " bytes for " + limit + " blocks";
  }
  return text + "unknown error";
}

std::size_t required_bytes(const PoolConfig& config) noexcept {
  if (!config_ok(config)) return 0;
  return control_bytes(config.block_count) +
         config.block_count * round_up(config.block_bytes, CACHE_LINE_BYTES);
}

Result<std::unique_ptr<BlockPool>, PoolError> BlockPool::create(const PoolConfig& config,
                                                                std::span<std::byte> memory) {
  const std::size_t needed = required_bytes(config);
  if (needed == 0) {
    return err(PoolError{PoolError::Code::BAD_CONFIG, config.name, "create", config.block_bytes,
                         config.block_count});
  }
  if (memory.size() < needed) {
    return err(
        PoolError{PoolError::Code::MEMORY_TOO_SMALL, config.name, "create", memory.size(), needed});
  }
  if (reinterpret_cast<std::uintptr_t>(memory.data()) % CACHE_LINE_BYTES != 0) {
    return err(PoolError{PoolError::Code::MEMORY_MISALIGNED, config.name, "create", memory.size(),
                         needed});
  }
  return std::unique_ptr<BlockPool>(new BlockPool(config, memory, nullptr));
}

Result<std::unique_ptr<BlockPool>, PoolError> BlockPool::create_owned(const PoolConfig& config) {
  const std::size_t needed = required_bytes(config);
  if (needed == 0) {
    return err(PoolError{PoolError::Code::BAD_CONFIG, config.name, "create", config.block_bytes,
                         config.block_count});
  }
  auto* memory = static_cast<std::byte*>(
      ::operator new (needed, std::align_val_t{CACHE_LINE_BYTES}, std::nothrow));
  if (memory == nullptr) {
    return err(PoolError{PoolError::Code::OUT_OF_MEMORY, config.name, "create", needed,
                         config.block_count});
  }
  auto pool = std::unique_ptr<BlockPool>(
      new BlockPool(config, std::span<std::byte>(memory, needed), memory));
  pool->owned_bytes_ = needed;
  return pool;
}

BlockPool::BlockPool(const PoolConfig& config, std::span<std::byte> memory,
                     std::byte* owned) noexcept
    : block_bytes_(config.block_bytes),
      block_stride_(round_up(config.block_bytes, CACHE_LINE_BYTES)),
      block_count_(config.block_count),
      name_(config.name),
      owned_(owned) {
  control_ = reinterpret_cast<Control*>(memory.data());
  blocks_ = memory.data() + control_bytes(block_count_);
  for (std::size_t i = 0; i < block_count_; ++i) {
    new (&control_[i]) Control{};
    control_[i].refs.store(0, std::memory_order_relaxed);
    control_[i].next.store(0, std::memory_order_relaxed);
  }
  // Push in reverse so that the first acquire returns block 0 (deterministic order when
  // single-threaded).
  for (std::size_t i = block_count_; i > 0; --i) push_free(static_cast<std::uint32_t>(i - 1));
}

BlockPool::~BlockPool() {
  OF_ENFORCE(free_count_.load() == block_count_,
             "BlockPool destroyed while handles are still alive");
  if (owned_ != nullptr) ::operator delete (owned_, std::align_val_t{CACHE_LINE_BYTES});
}

void BlockPool::push_free(std::uint32_t index) noexcept {
  std::uint64_t head = head_.load(std::memory_order_relaxed);
  std::uint64_t next_head = 0;
  do {
    control_[index].next.store(static_cast<std::uint32_t>(head & INDEX_MASK),
                               std::memory_order_relaxed);
    // The tag (high half) changes on every successful update, so a stale head never matches (ABA).
    next_head = (((head >> 32) + 1) << 32) | (std::uint64_t{index} + 1);
  } while (!head_.compare_exchange_weak(head, next_head, std::memory_order_release,
                                        std::memory_order_relaxed));
  free_count_.fetch_add(1, std::memory_order_relaxed);
}

Result<BlockHandle, PoolError> BlockPool::acquire(std::string_view requester,
                                                  std::size_t bytes) noexcept {
  if (bytes > block_bytes_) {
    return err(PoolError{PoolError::Code::TOO_LARGE, name_, requester, bytes, block_bytes_});
  }
  std::uint64_t head = head_.load(std::memory_order_acquire);
  std::uint64_t next_head = 0;
  std::uint32_t index = 0;
  do {
    const auto slot = static_cast<std::uint32_t>(head & INDEX_MASK);
    if (slot == 0)
      return err(PoolError{PoolError::Code::EXHAUSTED, name_, requester, bytes, block_count_});
    index = slot - 1;
    // Reading `next` of a block another thread just popped is benign: the tag makes our CAS fail.
    const std::uint32_t next = control_[index].next.load(std::memory_order_relaxed);
    next_head = (((head >> 32) + 1) << 32) | next;
  } while (!head_.compare_exchange_weak(head, next_head, std::memory_order_acquire,
                                        std::memory_order_acquire));
  free_count_.fetch_sub(1, std::memory_order_relaxed);
  control_[index].refs.store(1, std::memory_order_relaxed);
  return BlockHandle(this, index);
}

void BlockPool::add_ref(std::uint32_t index) noexcept {
  control_[index].refs.fetch_add(1, std::memory_order_relaxed);
}

void BlockPool::release(std::uint32_t index) noexcept {
  if (control_[index].refs.fetch_sub(1, std::memory_order_acq_rel) == 1) push_free(index);
}

std::byte* BlockPool::block_data(std::uint32_t index) const noexcept {
  return blocks_ + index * block_stride_;
}

BlockHandle::BlockHandle(const BlockHandle& other) noexcept
    : pool_(other.pool_), index_(other.index_) {
  if (pool_ != nullptr) pool_->add_ref(index_);
}

BlockHandle::BlockHandle(BlockHandle&& other) noexcept : pool_(other.pool_), index_(other.index_) {
  other.pool_ = nullptr;
}

BlockHandle& BlockHandle::operator=(const BlockHandle& other) noexcept {
  if (this != &other) {
    if (other.pool_ != nullptr) other.pool_->add_ref(other.index_);
    reset();
    pool_ = other.pool_;
    index_ = other.index_;
  }
  return *this;
}

BlockHandle& BlockHandle::operator=(BlockHandle&& other) noexcept {
  if (this != &other) {
    reset();
    pool_ = other.pool_;
    index_ = other.index_;
    other.pool_ = nullptr;
  }
  return *this;
}

BlockHandle::~BlockHandle() { reset(); }

void BlockHandle::reset() noexcept {
  if (pool_ != nullptr) pool_->release(index_);
  pool_ = nullptr;
}

std::span<std::byte> BlockHandle::bytes() const noexcept {
  if (pool_ == nullptr) return {};
  return {pool_->block_data(index_), pool_->block_bytes_};
}

std::uint32_t BlockHandle::use_count() const noexcept {
  return pool_ == nullptr ? 0 : pool_->control_[index_].refs.load(std::memory_order_relaxed);
}

}  // namespace orthoflow::memory_pool
