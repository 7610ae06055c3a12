// Fuzzes decode_schema (learning/detail/memory_codec.hpp): the schema record a perceptual memory's
// store and its export files carry (GOOD, bag of words, LDA, Local LDA with its topics, sets of
// spin images). No input
// may crash, leak or hit UB; a refusal says why; an accepted schema encodes to one that decodes to
// the same specification.
#include <cstdint>
#include <string>
#include <string_view>

#include "learning/detail/memory_codec.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view json(reinterpret_cast<const char*>(data), size);
  std::uint32_t version = 0;
  std::string why;
  const auto spec = orthoflow::learning::decode_schema(json, version, why);
  if (!spec) {
    if (why.empty()) { __builtin_trap(); }
    return 0;
  }
  std::uint32_t again_version = 0;
  std::string again_why;
  const auto again = orthoflow::learning::decode_schema(orthoflow::learning::encode_schema(*spec),
                                                        again_version, again_why);
  // encode_schema writes this build's version; everything else must come back equal.
  if (!again || !(*again == *spec) || again->describe() != spec->describe()) { __builtin_trap(); }
  return 0;
}
