// A robot's configuration checked (deploy/robot_config.hpp): every rule of the file format, and
// the character sets that keep each text inside its line and its quoting in the image's files
// (host names, addresses, paths, kernel parameters, package names, authorized keys). Reading the
// YAML is in robot_config.cpp.
#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <string>
#include <string_view>

#include "deploy/robot_config.hpp"

namespace orthoflow::deploy {
namespace {

bool letter_or_digit(char c) noexcept {
  return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9');
}

// True if @p text is min..max characters, each a letter, a digit or one of @p also.
bool made_of(std::string_view text, std::size_t min, std::size_t max, std::string_view also) {
  if (text.size() < min || text.size() > max) return false;
  for (const char c : text)
    if (!letter_or_digit(c) && also.find(c) == std::string_view::npos) return false;
  return true;
}

bool digits(std::string_view text, std::size_t max) {
  return !text.empty() && text.size() <= max &&
         text.find_first_not_of("0123456789") == std::string_view::npos;
}

// RFC 1123 host name label: lower-case letters, digits and '-', not at either end.
bool host_label(std::string_view text) {
  if (!made_of(text, 1, 63, "-") || text.front() == '-' || text.back() == '-') return false;
  for (const char c : text)
    if (c >= 'A' && c <= 'Z') return false;
  return true;
}

// a.b.c.d with each part 0..255.
bool ipv4(std::string_view text) {
  int parts = 0;
  std::size_t start = 0;
  while (true) {
    const std::size_t dot = text.find('.', start);
    const std::string_view part =
        text.substr(start, dot == std::string_view::npos ? dot : dot - start);
    if (!digits(part, 3) || std::atoi(std::string(part).c_str()) > 255) return false;
    ++parts;
    if (dot == std::string_view::npos) break;
    start = dot + 1;
  }
  return parts == 4;
}

bool cidr(std::string_view text) {
  const std::size_t slash = text.find('/');
  if (slash == std::string_view::npos || !ipv4(text.substr(0, slash))) return false;
  const std::string_view bits = text.substr(slash + 1);
  return digits(bits, 2) && std::atoi(std::string(bits).c_str()) <= 32;
}

Result<void, std::string> check_source(const std::string& s) {
  const auto with = [&](std::string_view head) {
    return s.rfind(head, 0) == 0 ? std::string_view(s).substr(head.size()) : std::string_view();
  };
  if (s == "auto" || s == "kinect" || s == "kinect-sim") return {};
  if (s.rfind("kinect-sim:", 0) == 0 && digits(with("kinect-sim:"), 10)) return {};
  if (s.rfind("synthetic:", 0) == 0 && digits(with("synthetic:"), 10)) return {};
  if (s.rfind("kinect:", 0) == 0 && s.rfind("kinect-sim", 0) != 0 &&
      made_of(with("kinect:"), 1, 32, ""))
    return {};
  return err("source: auto, kinect[:SERIAL], kinect-sim[:SEED] or synthetic:SEED, not '" + s + "'");
}

// A [ADDR:]PORT with ADDR a dotted IPv4 address and PORT 1..65535.
Result<void, std::string> check_listen(const std::string& listen) {
  const std::size_t colon = listen.rfind(':');
  const std::string port = colon == std::string::npos ? listen : listen.substr(colon + 1);
  if (colon != std::string::npos && !ipv4(std::string_view(listen).substr(0, colon)))
    return err("ui.listen: the address must be a dotted IPv4 address, not '" + listen + "'");
  if (!digits(port, 5) || std::atoi(port.c_str()) < 1 || std::atoi(port.c_str()) > 65535)
    return err("ui.listen: [ADDR:]PORT with PORT 1..65535, not '" + listen + "'");
  return {};
}

// A file beside the config on the build machine: a relative path inside the config's folder (no
// leading '/' or '~', no '..' component), printable, no quote, no new line. `orthoflow image`
// also resolves symbolic links and refuses a file they lead outside the folder.
bool inside_path(const std::string& p) {
  if (!made_of(p, 1, 4096, "/._-+@ ~") || p.front() == '/' || p.front() == '~') return false;
  for (std::size_t at = 0; at <= p.size();) {
    const std::size_t end = std::min(p.find('/', at), p.size());
    if (std::string_view(p).substr(at, end - at) == "..") return false;
    at = end + 1;
  }
  return true;
}

constexpr const char* INSIDE =
    "a relative path inside the config's folder (no leading '/' or '~', no '..'; letters, digits, "
    "/ "
    ". _ - + @ ~ and spaces)";

}  // namespace

Result<void, std::string> check_robot_config(const RobotConfig& c) {
  if (!host_label(c.hostname))
    return err("hostname: 1..63 lower-case letters, digits and '-' (not at either end), not '" +
               c.hostname + "'");
  if (auto ok = check_source(c.source); !ok) return ok;
  if (c.graph != "tabletop" && !inside_path(c.graph))
    return err("graph: 'tabletop' or a graph file's path: " + std::string(INSIDE) + ", not '" +
               c.graph + "'");
  if (c.learner != "instance" && c.learner != "bayes")
    return err("learner: instance or bayes, not '" + c.learner + "'");
  if (!std::isfinite(c.rate_hz) || (c.rate_hz != 0.0 && (c.rate_hz < 0.01 || c.rate_hz > 1000.0)))
    return err("rate_hz: 0 (the graph's period) or 0.01..1000");
  if (c.threads > 1024) return err("threads: 0..1024");
  if (c.ui.enabled) {
    if (auto ok = check_listen(c.ui.listen); !ok) return ok;
    if (!c.ui.token_file.empty() && !inside_path(c.ui.token_file))
      return err("ui.token_file: " + std::string(INSIDE) + ", not '" + c.ui.token_file + "'");
  }
  if (!c.admin.ssh_authorized_keys.empty() && !inside_path(c.admin.ssh_authorized_keys))
    return err("admin.ssh_authorized_keys: " + std::string(INSIDE) + ", not '" +
               c.admin.ssh_authorized_keys + "'");
  const NetworkSettings& n = c.network;
  if (n.interfaces.empty() || n.interfaces.size() > 16)
    return err("network.interfaces: 1..16 interface names or globs");
  for (const auto& i : n.interfaces)
    if (!made_of(i, 1, 15, "*?_.-"))
      return err("network.interfaces: '" + i +
                 "' is not an interface name or glob (1..15 of a-z 0-9 * ? _ . -)");
  if (n.dhcp) {
    if (!n.address.empty() || !n.gateway.empty() || !n.dns.empty())
      return err("network: address, gateway and dns are for dhcp: false");
  } else {
    if (!cidr(n.address))
      return err("network.address: a.b.c.d/n when dhcp is false, not '" + n.address + "'");
    if (!n.gateway.empty() && !ipv4(n.gateway))
      return err("network.gateway: a.b.c.d, not '" + n.gateway + "'");
  }
  if (n.dns.size() > 4) return err("network.dns: at most 4 resolvers");
  for (const auto& d : n.dns)
    if (!ipv4(d)) return err("network.dns: a.b.c.d, not '" + d + "'");
  const ImageSettings& im = c.image;
  if (im.esp_mib < 33 || im.esp_mib > 1024) return err("image.esp_mib: 33..1024");
  if (im.root_mib < 768 || im.root_mib > 65536) return err("image.root_mib: 768..65536");
  if (im.data_mib < 16 || im.data_mib > 1048576) return err("image.data_mib: 16..1048576");
  if (!im.console.empty() && !made_of(im.console, 1, 32, ",_"))
    return err("image.console: a tty and optional speed (ttyS0,115200), not '" + im.console + "'");
  if (im.cmdline.size() > 32) return err("image.cmdline: at most 32 kernel parameters");
  for (const auto& p : im.cmdline)
    if (!made_of(p, 1, 128, "=._,:/-+") || p.rfind("root=", 0) == 0 || p.rfind("init=", 0) == 0)
      return err(
          "image.cmdline: '" + p +
          "' (a kernel parameter of a-z 0-9 = . _ , : / - +; root= and init= are the image's own)");
  if (im.initramfs != "list" && im.initramfs != "most")
    return err("image.initramfs: list or most, not '" + im.initramfs + "'");
  if (im.packages.size() > 256) return err("image.packages: at most 256 packages");
  for (const auto& p : im.packages)
    if (!made_of(p, 2, 64, "+.-") || !letter_or_digit(p.front()) ||
        p.find_first_of("ABCDEFGHIJKLMNOPQRSTUVWXYZ") != std::string::npos)
      return err("image.packages: '" + p + "' is not a Debian package name");
  return {};
}

Result<void, std::string> check_authorized_keys(std::string_view text) {
  if (text.size() > 65536) return err("larger than 64 KiB");
  int keys = 0;
  int line_no = 0;
  std::size_t start = 0;
  while (start < text.size()) {
    std::size_t end = text.find('\n', start);
    if (end == std::string_view::npos) end = text.size();
    std::string_view line = text.substr(start, end - start);
    start = end + 1;
    ++line_no;
    if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
    if (line.empty() || line.front() == '#') continue;
    const std::size_t space = line.find(' ');
    const std::string_view type = line.substr(0, space);
    const bool known = type == "ssh-ed25519" || type == "ssh-rsa" ||
                       type.rfind("ecdsa-sha2-", 0) == 0 || type.rfind("sk-", 0) == 0;
    if (!known || space == std::string_view::npos || space + 1 >= line.size())
      return err("line " + std::to_string(line_no) +
                 ": not a public key (ssh-ed25519, ssh-rsa, ecdsa-sha2-*, sk-* followed by the "
                 "key; no options)");
    for (const char ch : line)
      if (static_cast<unsigned char>(ch) < 0x20 || static_cast<unsigned char>(ch) > 0x7e)
        return err("line " + std::to_string(line_no) + ": a character that is not printable ASCII");
    ++keys;
  }
  if (keys == 0) return err("no public key in it");
  return {};
}

}  // namespace orthoflow::deploy
