// Fuzzes parse_descriptor_cache (evaluation/descriptor_cache.hpp): no input may crash, leak or hit
// UB; a cache is either rejected whole (no entry) or accepted whole, and an accepted one re-encodes
// (paths sorted) and parses back with the same entries. The first input byte picks the descriptor
// length (1..8), the rest is the cache file.
#include <cstdint>
#include <span>
#include <string>

#include "evaluation/descriptor_cache.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size == 0) { return 0; }
  const std::size_t length = 1 + data[0] % 8;
  const std::span<const char> bytes(reinterpret_cast<const char*>(data) + 1, size - 1);
  const auto cache = orthoflow::evaluation::parse_descriptor_cache(bytes, length);
  if (cache.length != length) { __builtin_trap(); }
  if (cache.entries.empty()) { return 0; }
  const std::string again = orthoflow::evaluation::encode_descriptor_cache(cache);
  const auto back = orthoflow::evaluation::parse_descriptor_cache(again, length);
  if (back.entries.size() != cache.entries.size()) { __builtin_trap(); }
  for (const auto& [path, entry] : cache.entries) {
    const auto it = back.entries.find(path);
    if (it == back.entries.end() || !(it->second.stamp == entry.stamp) ||
        it->second.descriptor.size() != length) {
      __builtin_trap();
    }
  }
  return 0;
}
