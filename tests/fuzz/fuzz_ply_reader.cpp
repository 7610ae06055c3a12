// Fuzzes read_ply_buffer; an accepted model must have finite sizes and consistent buffers.
#include <cstdint>
#include <span>

#include "drivers/ply_reader.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  namespace ok = orthoflow::kernels;
  const std::span<const char> bytes(reinterpret_cast<const char*>(data), size);
  auto cloud = orthoflow::drivers::read_ply_buffer(bytes, "fuzz");
  if (!cloud) {
    if (cloud.error().message.empty()) { __builtin_trap(); }
    return 0;
  }
  const std::size_t n = cloud->size();
  if (cloud->y().size() != n || cloud->z().size() != n || cloud->organized()) { __builtin_trap(); }
  if (cloud->has(ok::Field::RGB) && cloud->rgb().size() != n) { __builtin_trap(); }
  return 0;
}
