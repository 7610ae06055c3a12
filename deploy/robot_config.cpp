#include "deploy/robot_config.hpp"

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <exception>

#include <yaml-cpp/yaml.h>

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

// A path on the build machine: printable, no quote, no new line (it is named in messages only).
bool host_path(const std::string& p) { return made_of(p, 1, 4096, "/._-+@ ~"); }

template <typename T>
Result<T, std::string> read_uint(const YAML::Node& v, const std::string& key, std::int64_t min,
                                 std::int64_t max) {
  const auto x = v.as<std::int64_t>();
  if (x < min || x > max)
    return err(key + ": " + std::to_string(min) + ".." + std::to_string(max) + ", not " +
               std::to_string(x));
  return static_cast<T>(x);
}

std::vector<std::string> string_list(const YAML::Node& v) {
  if (v.IsNull()) return {};
  return v.as<std::vector<std::string>>();
}

Result<void, std::string> read_ui(const YAML::Node& node, UiSettings& ui) {
  if (!node.IsMap()) return err("ui: a map (enabled, listen, token_file)");
  for (const auto& kv : node) {
    const std::string k = kv.first.as<std::string>();
    if (k == "enabled")
      ui.enabled = kv.second.as<bool>();
    else if (k == "listen")
      ui.listen = kv.second.as<std::string>();
    else if (k == "token_file")
      ui.token_file = kv.second.IsNull() ? "" : kv.second.as<std::string>();
    else
      return err("ui." + k + ": unknown key (enabled, listen, token_file)");
  }
  return {};
}

Result<void, std::string> read_network(const YAML::Node& node, NetworkSettings& n) {
  if (!node.IsMap()) return err("network: a map (dhcp, interfaces, address, gateway, dns)");
  for (const auto& kv : node) {
    const std::string k = kv.first.as<std::string>();
    if (k == "dhcp")
      n.dhcp = kv.second.as<bool>();
    else if (k == "interfaces")
      n.interfaces = string_list(kv.second);
    else if (k == "address")
      n.address = kv.second.IsNull() ? "" : kv.second.as<std::string>();
    else if (k == "gateway")
      n.gateway = kv.second.IsNull() ? "" : kv.second.as<std::string>();
    else if (k == "dns")
      n.dns = string_list(kv.second);
    else
      return err("network." + k + ": unknown key (dhcp, interfaces, address, gateway, dns)");
  }
  return {};
}

Result<void, std::string> read_admin(const YAML::Node& node, AdminSettings& a) {
  if (!node.IsMap()) return err("admin: a map (ssh_authorized_keys)");
  for (const auto& kv : node) {
    const std::string k = kv.first.as<std::string>();
    if (k == "ssh_authorized_keys")
      a.ssh_authorized_keys = kv.second.IsNull() ? "" : kv.second.as<std::string>();
    else
      return err("admin." + k + ": unknown key (ssh_authorized_keys)");
  }
  return {};
}

Result<void, std::string> read_image(const YAML::Node& node, ImageSettings& im) {
  if (!node.IsMap())
    return err("image: a map (esp_mib, root_mib, data_mib, console, cmdline, packages, initramfs)");
  for (const auto& kv : node) {
    const std::string k = kv.first.as<std::string>();
    const std::string key = "image." + k;
    if (k == "esp_mib") {
      auto v = read_uint<std::uint32_t>(kv.second, key, 33, 1024);
      if (!v) return err(v.error());
      im.esp_mib = *v;
    } else if (k == "root_mib") {
      auto v = read_uint<std::uint32_t>(kv.second, key, 768, 65536);
      if (!v) return err(v.error());
      im.root_mib = *v;
    } else if (k == "data_mib") {
      auto v = read_uint<std::uint32_t>(kv.second, key, 16, 1048576);
      if (!v) return err(v.error());
      im.data_mib = *v;
    } else if (k == "console") {
      im.console = kv.second.IsNull() ? "" : kv.second.as<std::string>();
    } else if (k == "cmdline") {
      im.cmdline = string_list(kv.second);
    } else if (k == "packages") {
      im.packages = string_list(kv.second);
    } else if (k == "initramfs") {
      im.initramfs = kv.second.as<std::string>();
    } else {
      return err(
          key +
          ": unknown key (esp_mib, root_mib, data_mib, console, cmdline, packages, initramfs)");
    }
  }
  return {};
}

}  // namespace

Result<Arch, std::string> parse_arch(std::string_view text) {
  if (text == "amd64") return Arch::amd64;
  if (text == "arm64") return Arch::arm64;
  return err("architecture must be amd64 or arm64, not '" + std::string(text) + "'");
}

std::string_view arch_name(Arch arch) noexcept { return arch == Arch::amd64 ? "amd64" : "arm64"; }

Result<RobotConfig, std::string> parse_robot_config(const std::string& text,
                                                    const std::string& name) {
  RobotConfig c;
  YAML::Node root;
  try {
    root = YAML::Load(text);
  } catch (const std::exception& e) { return err(name + ": not YAML: " + e.what()); }
  if (root.IsNull()) return err(name + ": empty (a map of robot settings; docs/DEPLOY.md)");
  if (!root.IsMap()) return err(name + ": a map of robot settings (docs/DEPLOY.md)");
  try {
    for (const auto& kv : root) {
      const std::string k = kv.first.as<std::string>();
      const YAML::Node& v = kv.second;
      Result<void, std::string> ok{};
      if (k == "hostname")
        c.hostname = v.as<std::string>();
      else if (k == "source")
        c.source = v.as<std::string>();
      else if (k == "graph")
        c.graph = v.as<std::string>();
      else if (k == "learner")
        c.learner = v.as<std::string>();
      else if (k == "rate_hz")
        c.rate_hz = v.as<double>();
      else if (k == "threads") {
        auto t = read_uint<std::uint32_t>(v, "threads", 0, 1024);
        if (!t) return err(name + ": " + t.error());
        c.threads = *t;
      } else if (k == "ui")
        ok = read_ui(v, c.ui);
      else if (k == "network")
        ok = read_network(v, c.network);
      else if (k == "admin")
        ok = read_admin(v, c.admin);
      else if (k == "image")
        ok = read_image(v, c.image);
      else
        return err(name + ": " + k +
                   ": unknown key (hostname, source, graph, learner, rate_hz, threads, ui, "
                   "network, admin, image)");
      if (!ok) return err(name + ": " + ok.error());
    }
  } catch (const YAML::Exception& e) { return err(name + ": " + e.what()); }
  if (auto ok = check_robot_config(c); !ok) return err(name + ": " + ok.error());
  return c;
}

Result<RobotConfig, std::string> load_robot_config(const std::string& path) {
  std::FILE* f = std::fopen(path.c_str(), "rb");
  if (f == nullptr) return err(path + ": cannot be read");
  std::string text;
  char buf[4096];
  std::size_t n = 0;
  while ((n = std::fread(buf, 1, sizeof buf, f)) > 0) {
    text.append(buf, n);
    if (text.size() > (1u << 20)) {
      std::fclose(f);
      return err(path + ": larger than 1 MiB");
    }
  }
  const bool failed = std::ferror(f) != 0;
  std::fclose(f);
  if (failed) return err(path + ": cannot be read");
  return parse_robot_config(text, path);
}

Result<void, std::string> check_robot_config(const RobotConfig& c) {
  if (!host_label(c.hostname))
    return err("hostname: 1..63 lower-case letters, digits and '-' (not at either end), not '" +
               c.hostname + "'");
  if (auto ok = check_source(c.source); !ok) return ok;
  if (c.graph != "tabletop" && !host_path(c.graph))
    return err(
        "graph: 'tabletop' or a graph file's path (letters, digits, / . _ - + @ ~ and spaces)");
  if (c.learner != "instance" && c.learner != "bayes")
    return err("learner: instance or bayes, not '" + c.learner + "'");
  if (!std::isfinite(c.rate_hz) || (c.rate_hz != 0.0 && (c.rate_hz < 0.01 || c.rate_hz > 1000.0)))
    return err("rate_hz: 0 (the graph's period) or 0.01..1000");
  if (c.threads > 1024) return err("threads: 0..1024");
  if (c.ui.enabled) {
    if (auto ok = check_listen(c.ui.listen); !ok) return ok;
    if (!c.ui.token_file.empty() && !host_path(c.ui.token_file))
      return err("ui.token_file: a path (letters, digits, / . _ - + @ ~ and spaces)");
  }
  if (!c.admin.ssh_authorized_keys.empty() && !host_path(c.admin.ssh_authorized_keys))
    return err("admin.ssh_authorized_keys: a path (letters, digits, / . _ - + @ ~ and spaces)");
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

std::uint16_t ui_port(const RobotConfig& c) noexcept {
  if (!c.ui.enabled) return 0;
  const std::size_t colon = c.ui.listen.rfind(':');
  const std::string port = colon == std::string::npos ? c.ui.listen : c.ui.listen.substr(colon + 1);
  return static_cast<std::uint16_t>(std::atoi(port.c_str()));
}

std::string kernel_console(const RobotConfig& c, Arch arch) {
  if (!c.image.console.empty()) return c.image.console;
  return arch == Arch::amd64 ? "ttyS0,115200" : "ttyAMA0,115200";
}

}  // namespace orthoflow::deploy
