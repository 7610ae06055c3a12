// Fuzzes parse_dictionary (learning/dictionary.hpp, the visual words' file): no input may crash,
// leak or hit UB; an accepted dictionary is consistent (words x dims values, its id recomputed) and
// re-encodes to the same bytes.
#include <cstdint>
#include <span>
#include <string>

#include "kernels/visual_words.hpp"
#include "learning/dictionary.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::span<const char> bytes(reinterpret_cast<const char*>(data), size);
  const auto d = orthoflow::learning::parse_dictionary(bytes);
  if (!d) {
    if (d.error().empty()) { __builtin_trap(); }
    return 0;
  }
  if (d->data.size() != d->words * d->dims || d->id != orthoflow::kernels::dictionary_id(*d)) {
    __builtin_trap();
  }
  if (orthoflow::learning::encode_dictionary(*d) != std::string(bytes.begin(), bytes.end())) {
    __builtin_trap();
  }
  return 0;
}
