#include "memory_pool/aligned_resource.hpp"

#include <algorithm>
#include <new>

namespace orthoflow::memory_pool {

void* AlignedResource::do_allocate(std::size_t bytes, std::size_t alignment) {
  const std::size_t align = std::max(alignment, CACHE_LINE_BYTES);
  return ::operator new (bytes, std::align_val_t{align});
}

void AlignedResource::do_deallocate(void* p, std::size_t /*bytes*/, std::size_t alignment) {
  const std::size_t align = std::max(alignment, CACHE_LINE_BYTES);
  ::operator delete (p, std::align_val_t{align});
}

bool AlignedResource::do_is_equal(const std::pmr::memory_resource& other) const noexcept {
  return dynamic_cast<const AlignedResource*>(&other) != nullptr;
}

std::pmr::memory_resource* aligned_resource() noexcept {
  // Leaked on purpose: containers destroyed during static destruction may still release into it.
  static auto* resource = new AlignedResource();
  return resource;
}

}  // namespace orthoflow::memory_pool
