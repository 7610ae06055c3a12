// Fuzzes the TUM RGB-D readers: depth.txt and associate.txt listings, and 16-bit depth PNGs (libpng
// behind orthoflow's checks). No input may crash, hang, leak or hit UB; a rejected input must say
// why; an accepted listing must hold relative PNG paths with no ".." component, in strictly
// increasing time.
#include <algorithm>
#include <cstdint>
#include <span>
#include <string_view>
#include <vector>

#include "formats/png_depth.hpp"
#include "formats/tum_rgbd.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size == 0) return 0;
  const std::uint8_t mode = data[0] % 4;
  const std::span<const char> rest(reinterpret_cast<const char*>(data) + 1, size - 1);
  if (mode < 2) {
    auto list = orthoflow::formats::parse_tum_depth_list(std::string_view(rest.data(), rest.size()),
                                                         "fuzz", mode == 1);
    if (!list) {
      if (list.error().message.empty()) __builtin_trap();
      return 0;
    }
    for (std::size_t k = 0; k < list->entries.size(); ++k) {
      const auto& e = list->entries[k];
      if (e.file.empty() || e.file.front() == '/') __builtin_trap();
      // No component is ".." ("a..b.png" is a name like any other).
      for (std::size_t at = 0; at <= e.file.size();) {
        const std::size_t end = std::min(e.file.find('/', at), e.file.size());
        if (e.file.compare(at, end - at, "..") == 0) __builtin_trap();
        at = end + 1;
      }
      if (k > 0 && !(e.seconds > list->entries[k - 1].seconds)) __builtin_trap();
    }
    return 0;
  }
  // A small image (fast) and the benchmark's size: any stream, any header.
  const std::uint32_t w = mode == 2 ? 16 : 640, h = mode == 2 ? 8 : 480;
  std::vector<std::uint16_t> out(std::size_t{w} * h);
  auto read = orthoflow::formats::parse_png_depth16(rest, "fuzz", w, h, out);
  if (!read && read.error().message.empty()) __builtin_trap();
  return 0;
}
