// Fuzzes read_pcd_buffer; whatever it accepts must survive a write/read round trip unchanged.
#include <cstdint>
#include <cstring>
#include <span>

#include "drivers/pcd_io.hpp"

namespace {

bool same_bits(std::span<const float> a, std::span<const float> b) {
  return a.size() == b.size() && (a.empty() || std::memcmp(a.data(), b.data(), a.size_bytes()) == 0);
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  namespace od = orthoflow::drivers;
  const std::span<const char> bytes(reinterpret_cast<const char*>(data), size);
  auto first = od::read_pcd_buffer(bytes, "fuzz");
  if (!first) {
    if (first.error().message.empty()) { __builtin_trap(); }
    return 0;
  }
  const std::string again = od::encode_pcd(*first, od::PcdEncoding::BINARY_COMPRESSED);
  auto second = od::read_pcd_buffer(again, "fuzz-again");
  if (!second || second->width() != first->width() || second->height() != first->height() ||
      !same_bits(first->x(), second->x()) || !same_bits(first->z(), second->z())) {
    __builtin_trap();
  }
  return 0;
}
