#include "kernels/capsule_mask.hpp"

#include "core/assert.hpp"
#include "kernels/detail/capsule_mask_kernel.hpp"

namespace orthoflow::kernels {

std::size_t capsule_mask_scalar(PointsView in, std::span<const Capsule> capsules,
                                std::span<std::uint8_t> mask) noexcept {
  OF_ASSERT(mask.size() >= in.size(), "capsule_mask: mask shorter than the input");
  detail::PreparedCapsule prepared[MAX_CAPSULES];
  const std::size_t count = detail::prepare_capsules(capsules, prepared);
  return detail::capsule_mask_range(in, prepared, count, mask.data(), 0, in.size());
}

std::size_t capsule_mask(PointsView in, std::span<const Capsule> capsules,
                         std::span<std::uint8_t> mask) noexcept {
  OF_ASSERT(mask.size() >= in.size(), "capsule_mask: mask shorter than the input");
  detail::PreparedCapsule prepared[MAX_CAPSULES];
  const std::size_t count = detail::prepare_capsules(capsules, prepared);
  static auto dispatched = xsimd::dispatch<SimdArchs>(detail::CapsuleMaskKernel{});
  return dispatched(in, static_cast<const detail::PreparedCapsule*>(prepared), count, mask);
}

}  // namespace orthoflow::kernels
