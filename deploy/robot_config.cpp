// A robot's configuration read (deploy/robot_config.hpp): robot.yaml over the defaults, key by
// key, each unknown key or wrong value an error naming it; and the values the image's files take
// from it (the architecture, the UI's port, the kernel console). The rules a config must satisfy
// are checked in robot_config_check.cpp.
#include "deploy/robot_config.hpp"

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <exception>

#include <yaml-cpp/yaml.h>

#include "core/regular_file.hpp"
#include "core/yaml_keys.hpp"

namespace orthoflow::deploy {
namespace {

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
  if (auto unique = core::check_unique_keys(root); !unique)
    return err(name + ": " + unique.error().to_string());
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
  // A regular file of at most 1 MiB, opened without blocking (core/regular_file.hpp).
  auto text = core::read_regular_text(path, std::size_t{1} << 20);
  if (!text) return err(path + ": cannot be read: " + text.error().message.substr(path.size() + 2));
  return parse_robot_config(*text, path);
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
