#include "kernels/packed_depth.hpp"

#include "core/assert.hpp"
#include "kernels/detail/packed_depth_kernel.hpp"

namespace orthoflow::kernels {

void unpack_11bit_scalar(std::span<const std::uint8_t> packed,
                         std::span<std::uint16_t> out) noexcept {
  OF_ASSERT(packed.size() >= packed_bytes(out.size(), 11), "unpack_11bit: packed input too short");
  detail::unpack_range_scalar<11>(packed.data(), 0, out.size(), out.data());
}

void unpack_11bit(std::span<const std::uint8_t> packed, std::span<std::uint16_t> out) noexcept {
  OF_ASSERT(packed.size() >= packed_bytes(out.size(), 11), "unpack_11bit: packed input too short");
  static auto dispatched = xsimd::dispatch<SimdArchs>(detail::UnpackKernel<11>{});
  dispatched(packed, out);
}

void unpack_10bit_scalar(std::span<const std::uint8_t> packed,
                         std::span<std::uint16_t> out) noexcept {
  OF_ASSERT(packed.size() >= packed_bytes(out.size(), 10), "unpack_10bit: packed input too short");
  detail::unpack_range_scalar<10>(packed.data(), 0, out.size(), out.data());
}

void unpack_10bit(std::span<const std::uint8_t> packed, std::span<std::uint16_t> out) noexcept {
  OF_ASSERT(packed.size() >= packed_bytes(out.size(), 10), "unpack_10bit: packed input too short");
  static auto dispatched = xsimd::dispatch<SimdArchs>(detail::UnpackKernel<10>{});
  dispatched(packed, out);
}

void pack_bits(std::span<const std::uint16_t> in, unsigned bits,
               std::span<std::uint8_t> out) noexcept {
  OF_ASSERT(bits == 10 || bits == 11, "pack_bits: the Kinect streams are 10 or 11 bits wide");
  OF_ASSERT(out.size() >= packed_bytes(in.size(), bits), "pack_bits: output too short");
  const std::uint32_t mask = (1U << bits) - 1U;
  // MSB-first: append each value below the pending bits, emit whole bytes from the top. Fewer than
  // 8 bits stay pending, so the accumulator never holds more than 7 + 11 bits.
  std::uint32_t pending = 0;
  unsigned pending_bits = 0;
  std::size_t o = 0;
  for (const std::uint16_t value : in) {
    pending = (pending << bits) | (value & mask);
    pending_bits += bits;
    while (pending_bits >= 8) {
      pending_bits -= 8;
      out[o++] = static_cast<std::uint8_t>(pending >> pending_bits);
    }
    pending &= (1U << pending_bits) - 1U;
  }
  if (pending_bits > 0) { out[o] = static_cast<std::uint8_t>(pending << (8 - pending_bits)); }
}

}  // namespace orthoflow::kernels
