#pragma once
/// @file
/// @brief SpscRing<T>: the one bounded single-producer / single-consumer ring of orthoflow
/// (learning commands and acknowledgements, durable teach jobs, JSON lines). Storage is allocated
/// once at construction; push and pop are wait-free, never allocate and never block. Several
/// producers share one ring through a lock of their own around push (see
/// graphs/channels/learning_channel.hpp): the consumer side stays lock-free.
#include <atomic>
#include <cstddef>
#include <memory>
#include <span>
#include <utility>

namespace orthoflow::core {

/// @brief Fixed-capacity FIFO of trivially copyable @p T.
/// @note Thread safety: at most one thread pushes and at most one thread pops at a time; any thread
/// may read size(). Indices grow without wrapping in practice (64-bit counters).
template <class T>
class SpscRing {
 public:
  /// @brief Allocates room for @p capacity elements (start-up only). @pre capacity > 0.
  explicit SpscRing(std::size_t capacity)
      : slots_(std::make_unique<T[]>(capacity)), capacity_(capacity) {}
  SpscRing(const SpscRing&) = delete;
  SpscRing& operator=(const SpscRing&) = delete;

  [[nodiscard]] std::size_t capacity() const noexcept { return capacity_; }
  /// @brief Elements queued now (exact for the producer or the consumer, a snapshot for others).
  [[nodiscard]] std::size_t size() const noexcept {
    return head_.load(std::memory_order_acquire) - tail_.load(std::memory_order_acquire);
  }

  /// @brief Producer: appends @p value. @return false (nothing changed) if the ring is full.
  bool try_push(const T& value) noexcept { return try_push_all(std::span<const T>(&value, 1)); }

  /// @brief Producer: appends all of @p values, or none of them if they do not fit. @return whether
  /// they did.
  bool try_push_all(std::span<const T> values) noexcept {
    const std::size_t head = head_.load(std::memory_order_relaxed);
    if (head - tail_.load(std::memory_order_acquire) + values.size() > capacity_) return false;
    for (std::size_t i = 0; i < values.size(); ++i) slots_[(head + i) % capacity_] = values[i];
    head_.store(head + values.size(), std::memory_order_release);
    return true;
  }

  /// @brief Producer: the next free slot to fill in place (nullptr when full); publish() makes it
  /// visible.
  [[nodiscard]] T* claim() noexcept {
    const std::size_t head = head_.load(std::memory_order_relaxed);
    return head - tail_.load(std::memory_order_acquire) == capacity_ ? nullptr
                                                                     : &slots_[head % capacity_];
  }
  /// @brief The slot (0 .. capacity - 1) of an element claim() or peek() returned, so that a caller
  /// can keep storage of its own per slot beside the ring (a slot's element and its storage are
  /// then owned by the same side at the same time).
  [[nodiscard]] std::size_t slot_of(const T* element) const noexcept {
    return static_cast<std::size_t>(element - slots_.get());
  }
  /// @brief Producer: publishes the slot claim() returned. @pre claim() returned non-null since the
  /// last publish.
  void publish() noexcept {
    head_.store(head_.load(std::memory_order_relaxed) + 1, std::memory_order_release);
  }

  /// @brief Consumer: takes the oldest element. @return false if the ring is empty.
  bool try_pop(T& out) noexcept {
    const T* front = peek();
    if (front == nullptr) return false;
    out = *front;
    release(1);
    return true;
  }
  /// @brief Consumer: the oldest element in place (nullptr when empty); release() frees it.
  [[nodiscard]] const T* peek() const noexcept {
    const std::size_t tail = tail_.load(std::memory_order_relaxed);
    return tail == head_.load(std::memory_order_acquire) ? nullptr : &slots_[tail % capacity_];
  }
  /// @brief Consumer: the queued elements as at most two contiguous runs (oldest first).
  [[nodiscard]] std::pair<std::span<const T>, std::span<const T>> readable() const noexcept {
    const std::size_t tail = tail_.load(std::memory_order_relaxed);
    const std::size_t n = head_.load(std::memory_order_acquire) - tail;
    const std::size_t start = tail % capacity_;
    const std::size_t first = n < capacity_ - start ? n : capacity_ - start;
    return {std::span<const T>(&slots_[start], first), std::span<const T>(&slots_[0], n - first)};
  }
  /// @brief Consumer: drops everything queued (with no producer pushing at the same time).
  void clear() noexcept {
    tail_.store(head_.load(std::memory_order_acquire), std::memory_order_release);
  }
  /// @brief Consumer: frees the @p n oldest elements. @pre n <= size().
  void release(std::size_t n) noexcept {
    tail_.store(tail_.load(std::memory_order_relaxed) + n, std::memory_order_release);
  }

 private:
  std::unique_ptr<T[]> slots_;
  std::size_t capacity_;
  alignas(64) std::atomic<std::size_t> head_{0};  // written by the producer
  alignas(64) std::atomic<std::size_t> tail_{0};  // written by the consumer
};

}  // namespace orthoflow::core
