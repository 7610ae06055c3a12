#pragma once
/// @file
/// @brief (internal) The header of every payload of the command channels, written and checked: the
/// first check of every payload another process wrote (the learning and
/// task command channels): whole, of its type and version, and saying its own size.
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <span>
#include <string>
#include <type_traits>

namespace orthoflow::graphs {

/// @brief Zeroes @p out (its padding too: it crosses processes) and writes its header: @p type_id,
/// @p version and its own size in payload_bytes.
template <class Payload>
void reset_payload_header(Payload& out, std::uint32_t type_id, std::uint16_t version) noexcept {
  static_assert(std::is_trivially_copyable_v<Payload>);
  std::memset(static_cast<void*>(&out), 0, sizeof out);
  out.type_id = type_id;
  out.version = version;
  out.payload_bytes = sizeof out;
}

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
