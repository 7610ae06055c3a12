#pragma once
/// @file
/// @brief The bridge's DDS side (issue 23): one Cyclone DDS participant on the configured domain
/// and network, and the four ROS 2 topics of a graph: objects and points out, learning commands in,
/// acknowledgements out, each with its configured QoS. Writes fill the generated messages from the
/// engine's payloads (ros_messages.hpp). One thread uses it.
#include <cstddef>
#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <string_view>

#include "bridge/bridge_config.hpp"
#include "bridge/command_relay.hpp"
#include "bridge/ros_messages.hpp"
#include "core/result.hpp"
#include "engine/frame_payload.hpp"
#include "engine/object_list_payload.hpp"

namespace orthoflow::bridge {

/// @brief What DDS itself reports about the bridge's topics.
struct DdsStatus {
  std::uint32_t objects_readers = 0;  ///< subscribers matched to the objects topic
  std::uint32_t points_readers = 0;
  std::uint32_t command_writers = 0;      ///< publishers matched to the commands topic
  std::uint32_t inconsistent_topics = 0;  ///< peers with another type under one of our topic names
  std::uint32_t commands_lost = 0;        ///< commands DDS reports lost before the bridge took them
  std::uint32_t commands_rejected = 0;    ///< commands DDS rejected (the reader's history limits)
};

class RosEndpoints {
 public:
  /// @brief Creates the domain (its Cyclone configuration from @p config), the participant, the
  /// topics and their writers and reader. @return Cyclone's error, named.
  [[nodiscard]] static Result<std::unique_ptr<RosEndpoints>, std::string> open(
      const BridgeConfig& config);
  ~RosEndpoints();
  RosEndpoints(const RosEndpoints&) = delete;
  RosEndpoints& operator=(const RosEndpoints&) = delete;

  /// @brief Publishes @p list on the objects topic. @return the message's data bytes (objects).
  Result<std::size_t, std::string> write_objects(const engine::ObjectListPayload& list);
  /// @brief Publishes @p frame on the points topic. @return the cloud's data bytes.
  Result<std::size_t, std::string> write_frame(const engine::FrameView& frame);
  /// @brief Takes at most @p max commands, handing each to @p on_command. @return how many.
  std::size_t take_commands(std::size_t max,
                            const std::function<void(const RosLearningCommand&)>& on_command);
  /// @brief Takes at most @p max arm stops (a reader only where commands are accepted), handing
  /// each one's reason to @p on_stop. @return how many.
  std::size_t take_arm_stops(std::size_t max,
                             const std::function<void(std::string_view reason)>& on_stop);
  /// @brief Publishes an arm stop's answer.
  Result<void, std::string> write_arm_stop_ack(const RosArmStopAck& ack);
  /// @brief Publishes the answer @p ack to @p route's sender.
  Result<void, std::string> write_ack(const graphs::RemoteAck& ack, const AckRoute& route,
                                      std::string_view problem);
  [[nodiscard]] DdsStatus status() const;
  [[nodiscard]] const BridgeTopics& topics() const noexcept { return topics_; }

 private:
  RosEndpoints() = default;
  BridgeTopics topics_;
  std::int32_t domain_entity_ = 0;
  std::int32_t participant_ = 0;
  std::int32_t objects_topic_ = 0, points_topic_ = 0, commands_topic_ = 0, acks_topic_ = 0;
  std::int32_t objects_writer_ = 0, points_writer_ = 0, commands_reader_ = 0, acks_writer_ = 0;
  std::int32_t arm_stop_topic_ = 0, arm_stop_ack_topic_ = 0;
  std::int32_t arm_stop_reader_ = 0, arm_stop_ack_writer_ = 0;
  std::uint32_t domain_ = 0;
  bool frames_ = false;
  StampClock clock_;
  RosScratch scratch_;
  AckScratch ack_scratch_;
};

/// @brief Cyclone's words for return code @p rc.
[[nodiscard]] std::string dds_error(std::int32_t rc);

}  // namespace orthoflow::bridge
