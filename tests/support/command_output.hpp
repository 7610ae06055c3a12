#pragma once
// Test support: run a shell command and keep its exit status and standard output (the CLI tests of
// tests/apps), and list a folder's PCD files in pcd_source's order.
#include <algorithm>
#include <array>
#include <cstdio>
#include <filesystem>
#include <string>
#include <vector>

namespace orthoflow::test {

struct CommandOutput {
  int status = -1;  ///< as pclose returns it (0: exit 0)
  std::string text;
};

/// Runs @p command with /bin/sh (add "2>&1" or "2>/dev/null" to it for standard error).
inline CommandOutput run_command(const std::string& command) {
  CommandOutput out;
  FILE* pipe = popen(command.c_str(), "r");
  if (pipe == nullptr) return out;
  std::array<char, 4096> buf{};
  std::size_t n = 0;
  while ((n = std::fread(buf.data(), 1, buf.size(), pipe)) > 0) out.text.append(buf.data(), n);
  out.status = pclose(pipe);
  return out;
}

/// The .pcd files of @p dir, sorted by name (pcd_source's order).
inline std::vector<std::filesystem::path> pcd_files(const std::filesystem::path& dir) {
  std::vector<std::filesystem::path> files;
  for (const auto& entry : std::filesystem::directory_iterator(dir))
    if (entry.path().extension() == ".pcd") files.push_back(entry.path());
  std::sort(files.begin(), files.end());
  return files;
}

}  // namespace orthoflow::test
