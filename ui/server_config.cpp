#include "ui/server_config.hpp"

#include <arpa/inet.h>

#include <charconv>
#include <fstream>
#include <random>

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

Result<std::string, std::string> read_token_file(const std::string& path) {
  std::ifstream in(path);
  if (!in) return err("--ui-token-file " + path + ": cannot be read");
  std::string line;
  std::getline(in, line);
  const auto first = line.find_first_not_of(" \t\r");
  const auto last = line.find_last_not_of(" \t\r");
  line = first == std::string::npos ? std::string{} : line.substr(first, last - first + 1);
  if (line.size() < 16) return err("--ui-token-file " + path + ": the token is shorter than 16");
  for (const char c : line) {
    if (c <= ' ' || c > '~')
      return err("--ui-token-file " + path + ": the token holds a space or a non-ASCII byte");
  }
  return line;
}

}  // namespace orthoflow::ui
