// Fuzzes read_pcd_buffer: no input may crash, leak or hit UB; a rejected input must say why; an
// accepted one must survive a write/read round trip in every encoding unchanged.
#include <cstdint>
#include <span>

#include "formats/pcd_io.hpp"
#include "fuzz_roundtrip.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::span<const char> bytes(reinterpret_cast<const char*>(data), size);
  auto cloud = orthoflow::formats::read_pcd_buffer(bytes, "fuzz");
  if (!cloud) {
    if (cloud.error().message.empty()) { __builtin_trap(); }
    return 0;
  }
  orthoflow_fuzz::check_pcd_round_trip(*cloud);
  return 0;
}
