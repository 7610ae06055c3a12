#pragma once
/// @file
/// @brief Allocation counting for the "no heap allocation after warm-up" tests. Include this header
/// in exactly ONE source file of a test binary: it replaces every global operator new and delete
/// (plain, array, aligned and nothrow) with versions that count while `g_counting` is set. All
/// forms are replaced so that ASan never sees memory from one allocator freed by another. What it
/// does not see: allocations that bypass operator new (malloc, oneTBB's own allocator).
#include <atomic>
#include <cstdint>
#include <cstdlib>
#include <new>
#include <thread>

namespace orthoflow::test {
inline std::atomic<bool> g_counting{false};
inline std::atomic<std::uint64_t> g_allocations{0};
/// When set (not the default id), only this thread's allocations count: a frame-path caller
/// beside a background thread that allocates by design (a file writer).
inline std::atomic<std::thread::id> g_counted_thread{};

inline void* counted_alloc(std::size_t size, std::size_t align) noexcept {
  if (g_counting.load(std::memory_order_relaxed)) {
    const std::thread::id only = g_counted_thread.load(std::memory_order_relaxed);
    if (only == std::thread::id{} || only == std::this_thread::get_id())
      g_allocations.fetch_add(1, std::memory_order_relaxed);
  }
  if (size == 0) size = 1;
  return align > alignof(std::max_align_t)
             ? std::aligned_alloc(align, (size + align - 1) / align * align)
             : std::malloc(size);
}

inline void* counted_alloc_or_throw(std::size_t size, std::size_t align) {
  void* p = counted_alloc(size, align);
  if (p == nullptr) throw std::bad_alloc();
  return p;
}
}  // namespace orthoflow::test

void* operator new(std::size_t n) { return orthoflow::test::counted_alloc_or_throw(n, 0); }
void* operator new[](std::size_t n) { return orthoflow::test::counted_alloc_or_throw(n, 0); }
void* operator new(std::size_t n, std::align_val_t a) {
  return orthoflow::test::counted_alloc_or_throw(n, static_cast<std::size_t>(a));
}
void* operator new[](std::size_t n, std::align_val_t a) {
  return orthoflow::test::counted_alloc_or_throw(n, static_cast<std::size_t>(a));
}
void* operator new(std::size_t n, const std::nothrow_t&) noexcept {
  return orthoflow::test::counted_alloc(n, 0);
}
void* operator new[](std::size_t n, const std::nothrow_t&) noexcept {
  return orthoflow::test::counted_alloc(n, 0);
}
void* operator new(std::size_t n, std::align_val_t a, const std::nothrow_t&) noexcept {
  return orthoflow::test::counted_alloc(n, static_cast<std::size_t>(a));
}
void* operator new[](std::size_t n, std::align_val_t a, const std::nothrow_t&) noexcept {
  return orthoflow::test::counted_alloc(n, static_cast<std::size_t>(a));
}
// The replaced deletes free what the replaced news malloc'd. GCC, once it inlines a delete into a
// `new T` expression's cleanup (at -O1 and above), sees free() on memory from operator new and
// warns (a false positive of GCC 12 with replaced operators): no mismatch here.
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wmismatched-new-delete"
void operator delete(void* p) noexcept { std::free(p); }
void operator delete[](void* p) noexcept { std::free(p); }
void operator delete(void* p, std::size_t) noexcept { std::free(p); }
void operator delete[](void* p, std::size_t) noexcept { std::free(p); }
void operator delete(void* p, std::align_val_t) noexcept { std::free(p); }
void operator delete[](void* p, std::align_val_t) noexcept { std::free(p); }
void operator delete(void* p, std::size_t, std::align_val_t) noexcept { std::free(p); }
void operator delete[](void* p, std::size_t, std::align_val_t) noexcept { std::free(p); }
void operator delete(void* p, const std::nothrow_t&) noexcept { std::free(p); }
void operator delete[](void* p, const std::nothrow_t&) noexcept { std::free(p); }
void operator delete(void* p, std::align_val_t, const std::nothrow_t&) noexcept { std::free(p); }
void operator delete[](void* p, std::align_val_t, const std::nothrow_t&) noexcept { std::free(p); }
#pragma GCC diagnostic pop
