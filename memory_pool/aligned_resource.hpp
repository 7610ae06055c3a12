#pragma once
/// @file
/// @brief A std::pmr memory resource that hands out 64-byte aligned storage.
/// Point clouds allocate through a std::pmr::memory_resource so that a pool (or shared memory)
/// can back them without changing their type.
#include <cstddef>
#include <memory_resource>

namespace orthoflow::memory_pool {

/// @brief Alignment of every buffer a point cloud owns: one cache line, enough for AVX-512 loads.
inline constexpr std::size_t CACHE_LINE_BYTES = 64;

/// @brief Heap-backed resource that aligns every allocation to at least CACHE_LINE_BYTES.
/// @note Thread-safe (it forwards to the global aligned operator new/delete).
class AlignedResource final : public std::pmr::memory_resource {
 private:
  void* do_allocate(std::size_t bytes, std::size_t alignment) override;
  void do_deallocate(void* p, std::size_t bytes, std::size_t alignment) override;
  [[nodiscard]] bool do_is_equal(const std::pmr::memory_resource& other) const noexcept override;
};

/// @brief The process-wide AlignedResource (never destroyed, safe to use from static destructors).
std::pmr::memory_resource* aligned_resource() noexcept;

}  // namespace orthoflow::memory_pool
