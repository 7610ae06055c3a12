#pragma once
/// @file
/// @brief (internal) The first check of every payload another process wrote (the learning and
/// task command channels): whole, of its type and version, and saying its own size.
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <span>
#include <string>
#include <type_traits>

namespace orthoflow::graphs {

/// @brief Copies @p bytes into @p out if they hold a whole @p Payload of @p type_id and
/// @p version whose payload_bytes is its size. @return false with the reason in @p error.
template <class Payload>
bool read_whole_payload(std::span<const std::byte> bytes, std::uint32_t type_id,
                        std::uint16_t version, Payload& out, std::string& error) {
  static_assert(std::is_trivially_copyable_v<Payload>);
  if (bytes.size() < sizeof(Payload)) {
    error = "payload of " + std::to_string(bytes.size()) + " bytes, expected " +
            std::to_string(sizeof(Payload));
    return false;
  }
  std::memcpy(&out, bytes.data(), sizeof(Payload));
  if (out.type_id != type_id || out.version != version) {
    error = "wrong payload type or version";
    return false;
  }
  if (out.payload_bytes != sizeof(Payload)) {
    error = "payload_bytes " + std::to_string(out.payload_bytes) + ", expected " +
            std::to_string(sizeof(Payload));
    return false;
  }
  return true;
}

}  // namespace orthoflow::graphs
