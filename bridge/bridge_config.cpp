#include "bridge/bridge_config.hpp"

#include <cmath>
#include <string_view>

#include <yaml-cpp/yaml.h>

#include "core/regular_file.hpp"
#include "core/yaml_keys.hpp"
#include "graphs/services/learning_ipc_bridge.hpp"

namespace orthoflow::bridge {
namespace {

// True if @p text is min..max characters, each a letter, a digit or one of @p also.
bool made_of(const std::string& text, std::size_t min, std::size_t max, std::string_view also) {
  if (text.size() < min || text.size() > max) return false;
  for (const char c : text) {
    const bool alnum = (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9');
    if (!alnum && also.find(c) == std::string_view::npos) return false;
  }
  return true;
}

// A ROS name token: a letter, then letters, digits and '_' (at most 64).
bool ros_token(const std::string& text) {
  return made_of(text, 1, 64, "_") &&
         ((text[0] >= 'a' && text[0] <= 'z') || (text[0] >= 'A' && text[0] <= 'Z'));
}

Result<void, std::string> read_qos(const YAML::Node& node, const std::string& key, TopicQos& out) {
  for (const auto& kv : node) {
    const std::string k = kv.first.as<std::string>();
    const std::string where = key + "." + k;
    if (k == "reliability") {
      const std::string v = kv.second.as<std::string>();
      if (v != "reliable" && v != "best_effort")
        return err(where + ": reliable or best_effort, not '" + v + "'");
      out.reliable = v == "reliable";
    } else if (k == "depth") {
      const auto v = kv.second.as<std::int64_t>();
      if (v < 1 || v > 1000) return err(where + ": 1..1000");
      out.depth = static_cast<std::uint32_t>(v);
    } else if (k == "durability") {
      const std::string v = kv.second.as<std::string>();
      if (v != "volatile" && v != "transient_local")
        return err(where + ": volatile or transient_local, not '" + v + "'");
      out.transient_local = v == "transient_local";
    } else {
      return err(where + ": unknown key (reliability, depth, durability)");
    }
  }
  return {};
}

}  // namespace

Result<BridgeConfig, std::string> load_bridge_config(const std::string& path, BridgeConfig c) {
  // A regular file of at most 1 MiB, never a FIFO waited on (core/regular_file.hpp).
  auto text = core::read_regular_text(path, std::size_t{1} << 20);
  if (!text) return err(text.error().message);
  YAML::Node root;
  try {
    root = YAML::Load(*text);
  } catch (const std::exception& e) { return err(path + ": " + e.what()); }
  if (auto unique = core::check_unique_keys(root); !unique)
    return err(path + ": " + unique.error().to_string());
  if (!root.IsMap()) return err(path + ": a map of bridge settings");
  try {
    for (const auto& kv : root) {
      const std::string k = kv.first.as<std::string>();
      const YAML::Node& v = kv.second;
      if (k == "graph")
        c.graph = v.as<std::string>();
      else if (k == "domain") {
        const auto d = v.as<std::int64_t>();
        if (d < 0 || d > 232) return err(path + ": domain: 0..232");
        c.domain = static_cast<std::uint32_t>(d);
      } else if (k == "interface")
        c.interface = v.as<std::string>();
      else if (k == "allow_network")
        c.allow_network = v.as<bool>();
      else if (k == "accept_network_commands")
        c.accept_network_commands = v.as<bool>();
      else if (k == "peers")
        c.peers = v.as<std::vector<std::string>>();
      else if (k == "frames")
        c.frames = v.as<bool>();
      else if (k == "max_frame_hz")
        c.max_frame_hz = v.as<double>();
      else if (k == "camera_frame")
        c.camera_frame = v.as<std::string>();
      else if (k == "topic_prefix")
        c.topic_prefix = v.as<std::string>();
      else if (k == "ack_timeout_ms")
        c.ack_timeout_ms = v.as<std::int64_t>();
      else if (k == "qos") {
        for (const auto& q : v) {
          const std::string t = q.first.as<std::string>();
          TopicQos* target = t == "objects"    ? &c.objects_qos
                             : t == "frames"   ? &c.frames_qos
                             : t == "commands" ? &c.commands_qos
                             : t == "acks"     ? &c.acks_qos
                                               : nullptr;
          if (target == nullptr)
            return err(path + ": qos." + t + ": unknown topic (objects, frames, commands, acks)");
          if (auto ok = read_qos(q.second, "qos." + t, *target); !ok)
            return err(path + ": " + ok.error());
        }
      } else {
        return err(path + ": " + k + ": unknown key");
      }
    }
  } catch (const YAML::Exception& e) { return err(path + ": " + e.what()); }
  if (auto ok = check_bridge_config(c); !ok) return err(path + ": " + ok.error());
  return c;
}

bool is_loopback(const std::string& interface) noexcept {
  return interface == "lo" || interface == "::1" || interface.rfind("127.", 0) == 0;
}

Result<void, std::string> check_bridge_config(const BridgeConfig& c) {
  if (auto topics = graphs::graph_topics(c.graph); !topics)
    return err("graph '" + c.graph + "': " + topics.error());
  if (c.domain > 232) return err("domain: 0..232");
  if (!ros_token(c.topic_prefix))
    return err("topic_prefix '" + c.topic_prefix + "': a ROS name token ([A-Za-z][A-Za-z0-9_]*)");
  if (!ros_token(c.graph))
    return err("graph '" + c.graph + "': a ROS topic needs [A-Za-z][A-Za-z0-9_]*");
  if (!made_of(c.camera_frame, 1, 100, "_/.-"))
    return err("camera_frame: 1..100 of [A-Za-z0-9_/.-]");
  if (!made_of(c.interface, 1, 100, "_.:-")) return err("interface: a name or an address");
  for (const std::string& p : c.peers)
    if (!made_of(p, 1, 100, "_.:-")) return err("peer '" + p + "': a host name or an address");
  if (!is_loopback(c.interface) && !c.allow_network)
    return err(
        "interface '" + c.interface +
        "' is not loopback: pass --allow-network (allow_network: true) to publish there; "
        "the bridge does not configure DDS Security yet, so anyone on that network reads the "
        "objects (docs/DDS.md)");
  if (!std::isfinite(c.max_frame_hz) || c.max_frame_hz < 0.0 || c.max_frame_hz > 1000.0)
    return err("max_frame_hz: 0..1000");
  if (c.ack_timeout_ms < 100 || c.ack_timeout_ms > 600000)
    return err("ack_timeout_ms: 100..600000");
  return {};
}

std::string cyclone_xml(const BridgeConfig& c) {
  const bool address = c.interface.find_first_of(".:") != std::string::npos;
  std::string xml = "<CycloneDDS><Domain Id=\"any\"><General><Interfaces><NetworkInterface ";
  xml += (address ? "address=\"" : "name=\"") + c.interface + "\"/></Interfaces>";
  // Loopback has no multicast: discovery goes to this host's ports; peers: to them only.
  const bool unicast = is_loopback(c.interface) || !c.peers.empty();
  xml += unicast ? "<AllowMulticast>false</AllowMulticast>" : "";
  xml += "</General><Discovery>";
  xml +=
      "<ParticipantIndex>auto</ParticipantIndex><MaxAutoParticipantIndex>50</"
      "MaxAutoParticipantIndex>";
  xml += "<Peers>";
  if (c.peers.empty() && is_loopback(c.interface)) xml += "<Peer Address=\"127.0.0.1\"/>";
  for (const std::string& p : c.peers) xml += "<Peer Address=\"" + p + "\"/>";
  xml += "</Peers></Discovery></Domain></CycloneDDS>";
  return xml;
}

BridgeTopics bridge_topics(const BridgeConfig& c) {
  const std::string base = "rt/" + c.topic_prefix + "/" + c.graph + "/";
  const std::string arm = "rt/" + c.topic_prefix + "/arm/";
  return {base + "objects",       base + "points", base + "learning_commands",
          base + "learning_acks", arm + "stop",    arm + "stop_ack"};
}

}  // namespace orthoflow::bridge
