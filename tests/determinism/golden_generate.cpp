// Writes the golden file of the determinism test: determinism_golden --out
// tests/golden/determinism.json Run it on x86-64 only (the reference architecture) and commit the
// result with the change that moved it.
#include <cstdio>
#include <cstring>
#include <exception>
#include <fstream>
#include <string>

#include "golden_outputs.hpp"

namespace {

// One line per entry (a scene, a view's descriptor), so a diff of the golden file shows what moved.
void write_golden(std::ofstream& file, const nlohmann::json& golden) {
  file << "{\n";
  std::size_t section = 0;
  for (const auto& [key, value] : golden.items()) {
    file << " \"" << key << "\": ";
    if (value.is_object()) {
      file << "{\n";
      std::size_t entry = 0;
      for (const auto& [name, item] : value.items()) {
        file << "  \"" << name << "\": " << item.dump() << (++entry < value.size() ? ",\n" : "\n");
      }
      file << " }";
    } else {
      file << value.dump();
    }
    file << (++section < golden.size() ? ",\n" : "\n");
  }
  file << "}\n";
}

}  // namespace

int main(int argc, char** argv) {
  std::string out;
  std::string shared = ORTHOFLOW_SHARED_DIR;
  for (int i = 1; i + 1 < argc; i += 2) {
    if (std::strcmp(argv[i], "--out") == 0) { out = argv[i + 1]; }
    if (std::strcmp(argv[i], "--shared") == 0) { shared = argv[i + 1]; }
  }
  if (out.empty()) {
    std::fprintf(stderr, "usage: %s --out FILE.json [--shared DIR]\n", argv[0]);
    return 2;
  }
  try {
    const nlohmann::json golden = orthoflow::testing::golden_all(shared);
    std::ofstream file(out);
    write_golden(file, golden);
    if (!file) {
      std::fprintf(stderr, "%s: cannot write\n", out.c_str());
      return 1;
    }
  } catch (const std::exception& e) {
    std::fprintf(stderr, "determinism_golden: %s\n", e.what());
    return 1;
  }
  std::printf("wrote %s\n", out.c_str());
  return 0;
}
