// Helper of memory_crash_test: opens the store given as argv[1], then teaches one view at a time
// and prints the stamp of every acknowledged teach on its own line, until it is killed (or argv[2]
// teaches). argv[3] "bow": the store is a bag-of-words store (test::bow_config, its dictionary
// stored with it).
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include "memory_test_util.hpp"

int main(int argc, char** argv) {
  using namespace orthoflow::learning;
  if (argc < 2) { return 2; }
  const long limit = argc > 2 ? std::strtol(argv[2], nullptr, 10) : 1000000L;
  const bool bow = argc > 3 && std::string(argv[3]) == "bow";
  auto memory_result =
      PerceptualMemory::open(argv[1], bow ? test::bow_config() : test::small_config());
  if (!memory_result) {
    std::fprintf(stderr, "%s\n", memory_result.error().to_string().c_str());
    return 1;
  }
  PerceptualMemory& memory = *memory_result;
  // Continue after the newest stored view: stamps are unique and increasing across restarts.
  std::int64_t next = 0;
  for (const CategoryEntry& c : memory.list()) {
    const auto views_result = memory.views_of(c.id);
    if (!views_result) { return 1; }
    for (const ViewRecord& v : *views_result) { next = std::max(next, v.stamp_ns + 1); }
  }
  for (long n = 0; n < limit; ++n, ++next) {
    const auto stamp = static_cast<std::uint64_t>(next);
    const std::string label = "c" + std::to_string(stamp % 5);
    if (!memory.teach(label, std::vector{test::make_view(75, stamp % 5 * 7, stamp)})) { return 1; }
    std::printf("%lld\n", static_cast<long long>(next));  // acknowledged: the synced write returned
    std::fflush(stdout);
  }
  return 0;
}
