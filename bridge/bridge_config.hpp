#pragma once
/// @file
/// @brief The DDS bridge's configuration (issue 23): the graph it serves, the DDS domain, the
/// network it binds, its peers and each topic's QoS; from a YAML file and the command line
/// (docs/DDS.md lists every key). Loopback by default: binding another interface is a deliberate
/// choice (--allow-network), because the bridge does not configure DDS Security yet (Debian ships
/// Cyclone's plugins in libddsc0debian/, but nothing sets up their certificates), so nothing on DDS
/// is authenticated,
/// and learning commands from such a network are taken only with --accept-network-commands.
#include <cstdint>
#include <string>
#include <vector>

#include "core/result.hpp"

namespace orthoflow::bridge {

/// @brief One topic's QoS: reliability, keep-last depth, durability.
struct TopicQos {
  bool reliable = true;
  std::uint32_t depth = 10;      ///< keep-last history, 1..1000
  bool transient_local = false;  ///< else volatile
};

struct BridgeConfig {
  std::string graph = "tabletop";        ///< iceoryx topics orthoflow/<graph>/...
  std::uint32_t domain = 0;              ///< DDS domain id, 0..232 (ROS_DOMAIN_ID)
  std::string interface = "lo";          ///< network interface name or address
  bool allow_network = false;            ///< needed for an interface other than loopback
  bool accept_network_commands = false;  ///< learning commands on a non-loopback interface
  std::vector<std::string> peers;        ///< unicast discovery addresses (no multicast then)
  bool frames = false;         ///< bridge the graph's frames (orthoflow/<graph>/frames) too
  double max_frame_hz = 30.0;  ///< frames thinned to at most this rate (0: all)
  std::string camera_frame = "camera_depth_optical_frame";  ///< header.frame_id
  std::string topic_prefix = "orthoflow";  ///< ROS names /<prefix>/<graph>/objects, ...
  TopicQos objects_qos{true, 10, false};
  TopicQos frames_qos{false, 1, false};
  TopicQos commands_qos{true, 64, false};
  TopicQos acks_qos{true, 64, false};
  std::int64_t ack_timeout_ms = 6000;  ///< a forwarded command unanswered this long: TIMEOUT
};

/// @brief Reads @p path (YAML) over @p base. Unknown keys, wrong types and values out of range
/// are errors naming the key.
[[nodiscard]] Result<BridgeConfig, std::string> load_bridge_config(const std::string& path,
                                                                   BridgeConfig base = {});
/// @brief Checks @p config: ranges, a graph name iceoryx takes, ROS-legal names, the loopback rule.
[[nodiscard]] Result<void, std::string> check_bridge_config(const BridgeConfig& config);
/// @brief True for "lo", "127.x.y.z" and "::1".
[[nodiscard]] bool is_loopback(const std::string& interface) noexcept;
/// @brief Cyclone DDS's XML configuration of @p config: the interface, multicast off with
/// unicast peers (loopback: this host), participant index auto.
[[nodiscard]] std::string cyclone_xml(const BridgeConfig& config);

/// @brief The DDS topic names (ROS 2 names with rmw_cyclonedds' "rt" prefix) of @p config.
struct BridgeTopics {
  std::string objects, points, learning_commands, learning_acks;
  std::string arm_stop, arm_stop_acks;  ///< rt/<prefix>/arm/stop, .../stop_ack (not per graph)
};
[[nodiscard]] BridgeTopics bridge_topics(const BridgeConfig& config);

}  // namespace orthoflow::bridge
