// Fuzzes read_ply_buffer: no input may crash, leak or hit UB; a rejected input must say why; an
// accepted model must have consistent unorganized buffers and survive a PCD write/read round trip.
#include <cstdint>
#include <span>

#include "formats/ply_reader.hpp"
#include "fuzz_roundtrip.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  namespace ok = orthoflow::kernels;
  const std::span<const char> bytes(reinterpret_cast<const char*>(data), size);
  auto cloud = orthoflow::formats::read_ply_buffer(bytes, "fuzz");
  if (!cloud) {
    if (cloud.error().message.empty()) { __builtin_trap(); }
    return 0;
  }
  const std::size_t n = cloud->size();
  if (cloud->y().size() != n || cloud->z().size() != n || cloud->organized()) { __builtin_trap(); }
  if (cloud->has(ok::Field::RGB) && cloud->rgb().size() != n) { __builtin_trap(); }
  orthoflow_fuzz::check_pcd_round_trip(*cloud);
  return 0;
}
