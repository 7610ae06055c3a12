// Fuzzes robot.yaml (deploy/robot_config.cpp, `orthoflow image check`, scripts/build_image.sh). No
// input may crash or hit UB; a configuration that parses renders files in which no value broke out
// of its line: the unit has exactly one ExecStart, the kernel command line is one line, and the
// host name file is one line.
#include <cstdint>
#include <cstdlib>
#include <string>

#include "deploy/image_files.hpp"
#include "deploy/robot_config.hpp"

namespace d = orthoflow::deploy;

namespace {

void check(bool ok) {
  if (!ok) std::abort();
}

std::size_t count(const std::string& text, const std::string& part) {
  std::size_t n = 0;
  for (std::size_t at = text.find(part); at != std::string::npos; at = text.find(part, at + 1)) ++n;
  return n;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  const auto config = d::parse_robot_config(text, "fuzz.yaml");
  if (!config) return 0;
  check(d::check_robot_config(config.value()).has_value());
  for (const auto& f : d::root_files(config.value())) {
    if (f.path == "etc/systemd/system/orthoflow.service") check(count(f.text, "\nExecStart=") == 1);
    if (f.path == "etc/hostname") check(count(f.text, "\n") == 1);
    if (f.path == "etc/orthoflow/image.env") check(count(f.text, "\n") == 6);
  }
  for (const d::Arch arch : {d::Arch::amd64, d::Arch::arm64}) {
    const std::string line = d::kernel_command_line(config.value(), arch);
    check(line.find('\n') == std::string::npos && line.find('\'') == std::string::npos &&
          line.find('"') == std::string::npos && line.find(';') == std::string::npos);
    check(count(d::grub_config(config.value(), arch), "\n  linux ") == 1);
  }
  return 0;
}
