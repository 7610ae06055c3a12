#pragma once
/// @file
/// @brief SnapshotCell<T>: one immutable T published by a writer and read without locks (RCU style
/// with hazard slots). A reader takes a free slot (one atomic exchange), announces the pointer it
/// is about to use in the slot and re-checks that it is still current; a writer swaps in the next
/// snapshot, retires the old one and frees every retired snapshot that no slot announces. At most
/// SNAPSHOT_READER_SLOTS snapshots can be pinned at once, so the retire list stays bounded (<=
/// slots + 1 entries). Why not std::atomic<std::shared_ptr>: libstdc++ 12 implements it with an
/// internal lock.
#include <array>
#include <atomic>
#include <cstddef>
#include <memory>
#include <thread>
#include <vector>

namespace orthoflow::learning {

/// @brief Readers that can hold a snapshot at the same instant; more wait (yield) for a free slot.
inline constexpr std::size_t SNAPSHOT_READER_SLOTS = 64;

/// @brief An atomically replaced immutable value. Readers: read(). Writer: publish(), serialised by
/// the caller (one writer at a time). @note Memory orders are seq_cst on the announce/re-check
/// pair, which is what makes hazard pointers correct (store-load ordering).
template <class T>
class SnapshotCell {
 public:
  /// @brief Pins one snapshot for as long as it lives. Move-only.
  class ReadGuard {
   public:
    ReadGuard(const SnapshotCell* cell, std::size_t slot, const T* value) noexcept
        : cell_(cell), slot_(slot), value_(value) {}
    ReadGuard(ReadGuard&& other) noexcept
        : cell_(other.cell_), slot_(other.slot_), value_(other.value_) {
      other.cell_ = nullptr;
    }
    ReadGuard(const ReadGuard&) = delete;
    ReadGuard& operator=(const ReadGuard&) = delete;
    ReadGuard& operator=(ReadGuard&&) = delete;
    ~ReadGuard() {
      if (cell_ != nullptr) { cell_->release(slot_); }
    }
    [[nodiscard]] const T& operator*() const noexcept { return *value_; }
    [[nodiscard]] const T* operator->() const noexcept { return value_; }

   private:
    const SnapshotCell* cell_;
    std::size_t slot_;
    const T* value_;
  };

  /// @brief Starts with @p initial as the current snapshot. @pre initial != nullptr
  explicit SnapshotCell(std::unique_ptr<const T> initial) : current_(initial.release()) {
    retired_.reserve(SNAPSHOT_READER_SLOTS + 1);
  }
  SnapshotCell(const SnapshotCell&) = delete;
  SnapshotCell& operator=(const SnapshotCell&) = delete;
  /// @pre no ReadGuard is alive.
  ~SnapshotCell() {
    delete current_.load();
    for (const T* old : retired_) { delete old; }
  }

  /// @brief Pins the current snapshot. @p slot_hint: where to look for a free slot first (updated).
  /// @note Lock-free, no allocation; thread-safe.
  [[nodiscard]] ReadGuard read(std::size_t& slot_hint) const noexcept {
    const std::size_t slot = acquire_slot(slot_hint);
    slot_hint = slot;
    const T* value = current_.load(std::memory_order_seq_cst);
    for (;;) {
      slots_[slot].hazard.store(value, std::memory_order_seq_cst);
      const T* again = current_.load(std::memory_order_seq_cst);
      if (again == value) { break; }
      value = again;
    }
    return ReadGuard(this, slot, value);
  }

  /// @brief The current snapshot, for the (single, serialised) writer that is about to replace it.
  [[nodiscard]] const T& writer_view() const noexcept {
    return *current_.load(std::memory_order_acquire);
  }

  /// @brief Makes @p next current (visible to every read() that starts after this returns) and
  /// frees the retired snapshots no reader holds. @pre next != nullptr; writers serialised by the
  /// caller.
  void publish(std::unique_ptr<const T> next) {
    const T* old = current_.exchange(next.release(), std::memory_order_seq_cst);
    retired_.push_back(old);
    std::array<const T*, SNAPSHOT_READER_SLOTS> pinned{};
    for (std::size_t s = 0; s < SNAPSHOT_READER_SLOTS; ++s) {
      pinned[s] = slots_[s].hazard.load(std::memory_order_seq_cst);
    }
    std::size_t kept = 0;
    for (const T* candidate : retired_) {
      bool in_use = false;
      for (const T* p : pinned) { in_use = in_use || p == candidate; }
      if (in_use) {
        retired_[kept++] = candidate;
      } else {
        delete candidate;
      }
    }
    retired_.resize(kept);
    retired_count_.store(kept, std::memory_order_relaxed);
  }

  /// @brief Retired snapshots still pinned by a reader after the last publish(). @note Thread-safe.
  [[nodiscard]] std::size_t retired_pending() const noexcept {
    return retired_count_.load(std::memory_order_relaxed);
  }

 private:
  struct alignas(64) Slot {
    std::atomic<bool> busy{false};
    std::atomic<const T*> hazard{nullptr};
  };

  std::size_t acquire_slot(std::size_t hint) const noexcept {
    for (;;) {
      for (std::size_t k = 0; k < SNAPSHOT_READER_SLOTS; ++k) {
        const std::size_t s = (hint + k) % SNAPSHOT_READER_SLOTS;
        if (!slots_[s].busy.load(std::memory_order_relaxed) &&
            !slots_[s].busy.exchange(true, std::memory_order_acquire)) {
          return s;
        }
      }
      std::this_thread::yield();  // more than SNAPSHOT_READER_SLOTS concurrent readers: wait for
                                  // one to leave
    }
  }
  void release(std::size_t slot) const noexcept {
    slots_[slot].hazard.store(nullptr, std::memory_order_release);
    slots_[slot].busy.store(false, std::memory_order_release);
  }

  mutable std::array<Slot, SNAPSHOT_READER_SLOTS> slots_{};
  std::atomic<const T*> current_;
  std::vector<const T*> retired_;  // writer only
  std::atomic<std::size_t> retired_count_{0};
};

}  // namespace orthoflow::learning
