#pragma once
// SIMD body of capsule_mask(): per lane, the squared distance to each capsule's segment in the
// scalar rule's operation order (compiled with -ffp-contract=off: no fused multiply-adds).
#include "kernels/detail/capsule_mask_kernel.hpp"

namespace orthoflow::kernels::detail {

template <class Arch>
std::size_t CapsuleMaskKernel::operator()(Arch /*arch*/, PointsView in, const PreparedCapsule* caps,
                                          std::size_t count,
                                          std::span<std::uint8_t> mask) const noexcept {
  using batch = xsimd::batch<float, Arch>;
  constexpr std::size_t LANES = batch::size;
  const std::size_t n = in.size();
  const batch zero(0.0F);
  const batch one(1.0F);
  std::size_t removed = 0;
  std::size_t i = 0;
  for (; i + LANES <= n; i += LANES) {
    const batch x = batch::load_unaligned(in.x.data() + i);
    const batch y = batch::load_unaligned(in.y.data() + i);
    const batch z = batch::load_unaligned(in.z.data() + i);
    xsimd::batch_bool<float, Arch> inside(false);
    for (std::size_t k = 0; k < count; ++k) {
      const PreparedCapsule& c = caps[k];
      const batch px = x - batch(c.ax);
      const batch py = y - batch(c.ay);
      const batch pz = z - batch(c.az);
      const batch dot = px * batch(c.dx) + py * batch(c.dy) + pz * batch(c.dz);
      const batch t = xsimd::min(xsimd::max(dot * batch(c.inv_len2), zero), one);
      const batch ex = px - t * batch(c.dx);
      const batch ey = py - t * batch(c.dy);
      const batch ez = pz - t * batch(c.dz);
      inside = inside || ((ex * ex + ey * ey + ez * ez) <= batch(c.r2));
    }
    alignas(64) float lane[LANES];
    xsimd::select(inside, zero, one).store_aligned(lane);
    for (std::size_t l = 0; l < LANES; ++l) {
      mask[i + l] = lane[l] != 0.0F ? 1 : 0;
      removed += lane[l] != 0.0F ? 0U : 1U;
    }
  }
  return removed + capsule_mask_range(in, caps, count, mask.data(), i, n);
}

}  // namespace orthoflow::kernels::detail

#ifdef OF_SIMD_ARCH
template std::size_t orthoflow::kernels::detail::CapsuleMaskKernel::operator()<OF_SIMD_ARCH>(
    OF_SIMD_ARCH, orthoflow::kernels::PointsView,
    const orthoflow::kernels::detail::PreparedCapsule*, std::size_t,
    std::span<std::uint8_t>) const noexcept;
#endif
