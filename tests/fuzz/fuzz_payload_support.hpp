#pragma once
// What the payload fuzzers share (fuzz_learning_payloads.cpp, fuzz_task_payloads.cpp): a payload
// filled from the fuzzer's bytes over a fresh header (made right again when asked, so the fuzzer
// reaches the fields behind it), and its bytes, whole or cut.
#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <memory>
#include <span>

namespace orthoflow::fuzz {

/// @p Payload's reset_header is found by argument-dependent lookup (graphs::reset_header).
template <class Payload>
std::unique_ptr<Payload> filled(const std::uint8_t* data, std::size_t size, bool fix_header) {
  auto p = std::make_unique<Payload>();
  reset_header(*p);
  std::memcpy(static_cast<void*>(p.get()), data, std::min(size, sizeof(Payload)));
  if (fix_header) {
    Payload fresh;
    reset_header(fresh);
    p->type_id = fresh.type_id;
    p->version = fresh.version;
    p->payload_bytes = fresh.payload_bytes;
  }
  return p;
}

template <class Payload>
std::span<const std::byte> bytes_of(const Payload& p, std::size_t size) {
  return {reinterpret_cast<const std::byte*>(&p), std::min(size, sizeof(Payload))};
}

}  // namespace orthoflow::fuzz
