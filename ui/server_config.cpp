#include "ui/server_config.hpp"

#include <arpa/inet.h>
#include <unistd.h>

#include <charconv>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <random>

#include "core/regular_file.hpp"

namespace orthoflow::ui {

namespace {
bool is_ipv4(const std::string& text) {
  in_addr parsed{};
  return ::inet_pton(AF_INET, text.c_str(), &parsed) == 1;
}
}  // namespace

Result<void, std::string> parse_listen(std::string_view text, UiServerConfig& config) {
  const std::size_t colon = text.rfind(':');
  const std::string address =
      colon == std::string_view::npos ? config.address : std::string(text.substr(0, colon));
  const std::string_view port_text =
      colon == std::string_view::npos ? text : text.substr(colon + 1);
  unsigned port = 0;
  const auto [end, ec] =
      std::from_chars(port_text.data(), port_text.data() + port_text.size(), port);
  if (port_text.empty() || ec != std::errc{} || end != port_text.data() + port_text.size() ||
      port > 65535)
    return err("'" + std::string(text) + "': the port must be a number from 0 to 65535");
  if (address != "localhost" && !is_ipv4(address))
    return err("'" + std::string(text) + "': the address must be an IPv4 address or localhost");
  config.address = address == "localhost" ? "127.0.0.1" : address;
  config.port = static_cast<std::uint16_t>(port);
  return {};
}

std::string generate_token() {
  std::random_device device;
  std::uniform_int_distribution<int> byte(0, 255);
  static constexpr char HEX[] = "0123456789abcdef";
  std::string token;
  for (std::size_t i = 0; i < TOKEN_BYTES; ++i) {
    const int b = byte(device);
    token += HEX[b >> 4];
    token += HEX[b & 15];
  }
  return token;
}

Result<std::string, std::string> write_private_token(const std::string& token) {
  std::string path =
      (std::filesystem::temp_directory_path() / "orthoflow-ui-token-XXXXXX").string();
  const int fd = ::mkstemp(path.data());  // 0600, O_EXCL
  if (fd < 0) return err("cannot create a private file for the generated token in " + path);
  const std::string line = token + "\n";
  const bool written = ::write(fd, line.data(), line.size()) == static_cast<ssize_t>(line.size());
  ::close(fd);
  if (!written) {
    ::unlink(path.c_str());
    return err("cannot write the generated token to " + path);
  }
  return path;
}

Result<std::string, std::string> read_token_file(const std::string& path) {
  // A regular file of at most 4 KiB, opened without blocking: a FIFO or /dev/zero is refused at
  // once.
  auto text = core::read_regular_text(path, 4096);
  if (!text) return err("--ui-token-file " + text.error().message);
  return token_from_text(*text, "--ui-token-file " + path);
}

Result<std::string, std::string> token_from_text(const std::string& text, const std::string& what) {
  std::string line = text.substr(0, text.find('\n'));
  const auto first = line.find_first_not_of(" \t\r");
  const auto last = line.find_last_not_of(" \t\r");
  line = first == std::string::npos ? std::string{} : line.substr(first, last - first + 1);
  if (line.size() < 16) return err(what + ": the token is shorter than 16");
  for (const char c : line) {
    if (c <= ' ' || c > '~') return err(what + ": the token holds a space or a non-ASCII byte");
  }
  return line;
}

}  // namespace orthoflow::ui
