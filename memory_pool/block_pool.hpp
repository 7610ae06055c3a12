#pragma once
/// @file
/// @brief BlockPool: fixed-size blocks carved once from caller-provided memory, handed out
/// lock-free through reference-counted BlockHandles (STYLE rule 8; iceoryx mepoo MemPool is the
/// model).
#include <atomic>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <span>
#include <string>
#include <string_view>

#include "core/result.hpp"

namespace orthoflow::memory_pool {

/// @brief Start-up configuration of one pool. Validated once by BlockPool::create.
struct PoolConfig {
  std::size_t block_bytes = 4096;  ///< usable bytes per block (rounded up to 64 internally)
  std::size_t block_count = 8;     ///< number of blocks; at most MAX_BLOCKS
  std::string_view name = "pool";  ///< shows up in error messages (must outlive the pool)
};

/// @brief Upper bound on blocks per pool (indices are 32-bit, the free-list head is tagged).
inline constexpr std::size_t MAX_BLOCKS = std::size_t{1} << 24;
/// @brief Upper bound on one block (1 GiB): larger requests are configuration errors, not
/// allocations.
inline constexpr std::size_t MAX_BLOCK_BYTES = std::size_t{1} << 30;

/// @brief Why a pool could not be created or a block could not be handed out.
/// Holds only views and numbers so that building it on the frame path never allocates.
struct PoolError {
  enum class Code {
    EXHAUSTED,
    TOO_LARGE,
    BAD_CONFIG,
    MEMORY_TOO_SMALL,
    MEMORY_MISALIGNED,
    OUT_OF_MEMORY
  };
  Code code = Code::BAD_CONFIG;
  std::string_view pool;       ///< name of the pool
  std::string_view requester;  ///< who asked (a node name, "create", ...)
  std::size_t bytes = 0;       ///< bytes requested (or provided, for MEMORY_TOO_SMALL)
  std::size_t limit = 0;       ///< block size, block count or bytes needed, depending on code
};

/// @brief Short name of an error code, e.g. "EXHAUSTED".
[[nodiscard]] std::string_view to_string(PoolError::Code code) noexcept;
/// @brief Full message naming pool, requester and size. Allocates: call off the frame path.
[[nodiscard]] std::string to_string(const PoolError& error);

/// @brief Bytes of external memory a pool with this configuration needs (control words + blocks),
/// or 0 if the configuration is invalid. @pre none.
[[nodiscard]] std::size_t required_bytes(const PoolConfig& config) noexcept;

class BlockPool;

/// @brief Shared ownership of one block. Copying adds a reference (atomic); the block returns to
/// its pool when the last handle is destroyed or reset. An empty handle owns nothing.
/// @note Thread-safe like std::shared_ptr: distinct handles may be used from different threads.
class BlockHandle {
 public:
  BlockHandle() noexcept = default;
  BlockHandle(const BlockHandle& other) noexcept;
  BlockHandle(BlockHandle&& other) noexcept;
  BlockHandle& operator=(const BlockHandle& other) noexcept;
  BlockHandle& operator=(BlockHandle&& other) noexcept;
  ~BlockHandle();

  /// @brief Drops this reference (returns the block if it was the last one).
  void reset() noexcept;
  [[nodiscard]] explicit operator bool() const noexcept { return pool_ != nullptr; }
  /// @brief The block's bytes (empty span for an empty handle).
  [[nodiscard]] std::span<std::byte> bytes() const noexcept;
  /// @brief Current number of handles sharing the block (0 for an empty handle). Racy by nature.
  [[nodiscard]] std::uint32_t use_count() const noexcept;
  [[nodiscard]] std::uint32_t index() const noexcept { return index_; }

 private:
  friend class BlockPool;
  BlockHandle(BlockPool* pool, std::uint32_t index) noexcept : pool_(pool), index_(index) {}
  BlockPool* pool_ = nullptr;
  std::uint32_t index_ = 0;
};

/// @brief A fixed set of equally sized blocks living in memory the pool does not own.
/// acquire() and handle release are lock-free (a Treiber stack of indices whose head carries an
/// ABA tag) and may be called from any thread. Never blocks, never falls back to the heap.
/// @pre Every handle is released before the pool (and its memory) is destroyed (OF_ENFORCE).
class BlockPool {
 public:
  /// @brief Carves a pool out of `memory`, which must hold required_bytes(config) bytes and be
  /// 64-byte aligned; the caller keeps it alive (heap, shared memory, iceoryx chunk...).
  [[nodiscard]] static Result<std::unique_ptr<BlockPool>, PoolError> create(
      const PoolConfig& config, std::span<std::byte> memory);
  /// @brief Same, but the pool allocates (once, now) and owns its memory.
  [[nodiscard]] static Result<std::unique_ptr<BlockPool>, PoolError> create_owned(
      const PoolConfig& config);
  ~BlockPool();
  BlockPool(const BlockPool&) = delete;
  BlockPool& operator=(const BlockPool&) = delete;

  /// @brief Takes a free block able to hold `bytes`. @return EXHAUSTED or TOO_LARGE naming
  /// `requester` and `bytes` on failure. Lock-free, no allocation.
  [[nodiscard]] Result<BlockHandle, PoolError> acquire(std::string_view requester,
                                                       std::size_t bytes) noexcept;

  [[nodiscard]] std::size_t block_bytes() const noexcept { return block_bytes_; }
  [[nodiscard]] std::size_t block_count() const noexcept { return block_count_; }
  /// @brief Blocks currently free (exact when no other thread is acquiring/releasing).
  [[nodiscard]] std::size_t free_count() const noexcept {
    return free_count_.load(std::memory_order_relaxed);
  }
  [[nodiscard]] std::string_view name() const noexcept { return name_; }

 private:
  friend class BlockHandle;
  struct Control;  // per-block reference count and free-list link, stored in the external memory
  BlockPool(const PoolConfig& config, std::span<std::byte> memory, std::byte* owned) noexcept;
  void add_ref(std::uint32_t index) noexcept;
  void release(std::uint32_t index) noexcept;
  void push_free(std::uint32_t index) noexcept;
  [[nodiscard]] std::byte* block_data(std::uint32_t index) const noexcept;

  Control* control_ = nullptr;
  std::byte* blocks_ = nullptr;
  std::size_t block_bytes_ = 0;   // as configured
  std::size_t block_stride_ = 0;  // rounded up to a cache line
  std::size_t block_count_ = 0;
  std::string_view name_;
  std::byte* owned_ = nullptr;  // memory to free in the destructor (create_owned only)
  std::size_t owned_bytes_ = 0;
  alignas(64) std::atomic<std::uint64_t> head_{0};  // (tag << 32) | (index + 1); index 0 = empty
  std::atomic<std::size_t> free_count_{0};
};

}  // namespace orthoflow::memory_pool
