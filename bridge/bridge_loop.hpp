#pragma once
/// @file
/// @brief The DDS bridge's loop (issue 23): a running graph's object lists (and frames) from
/// iceoryx to DDS, learning commands from DDS through the CommandRelay into the graph, and the
/// graph's acks back. One thread calls pump(); it never blocks (iceoryx and DDS takes are
/// non-blocking) and each pass is bounded (at most 16 object lists, 1 frame, 64 commands and 64
/// acks). The graph restarting underneath is invisible here (iceoryx reconnects its topics); a lost
/// RouDi is the caller's to notice (engine::ipc_roudi_lost). Arm stops from DDS go to the process
/// holding the arm (arm_stop_relay.hpp).
#include <cstdint>
#include <memory>
#include <string>

#include "bridge/arm_stop_relay.hpp"
#include "bridge/bridge_config.hpp"
#include "bridge/command_relay.hpp"
#include "bridge/ros_endpoints.hpp"
#include "core/result.hpp"
#include "engine/ipc_pubsub.hpp"
#include "engine/telemetry.hpp"

namespace orthoflow::bridge {

/// @brief What the bridge did. Read on the pump's thread (or after it stopped).
struct BridgeCounters {
  std::uint64_t objects_out = 0, frames_out = 0, frames_thinned = 0, frames_bad = 0;
  std::uint64_t data_bytes_out = 0;  ///< objects' and clouds' data handed to DDS
  std::uint64_t write_errors = 0;
  std::uint64_t commands_in = 0, commands_forwarded = 0, commands_invalid = 0;
  std::uint64_t commands_no_graph = 0, commands_queue_full = 0;
  std::uint64_t acks_out = 0, acks_timeout = 0;
  std::uint64_t arm_stops_in = 0, arm_stops_confirmed = 0;  ///< DDS stops, and holders' answers
};

class BridgeLoop {
 public:
  /// @brief Subscribes to the graph's topics and opens the DDS side. @pre the iceoryx runtime is
  /// initialised. @param client the bridge's iceoryx client id (non-zero).
  [[nodiscard]] static Result<std::unique_ptr<BridgeLoop>, std::string> open(
      const BridgeConfig& config, std::uint64_t client);
  ~BridgeLoop();

  /// @brief One bounded pass at @p now_ns (steady clock). @return how much it moved (0: idle).
  std::size_t pump(std::int64_t now_ns);

  [[nodiscard]] const BridgeCounters& counters() const noexcept { return counters_; }
  /// @brief The engine's telemetry format: one row per direction (objects, points, commands,
  /// acks), latency = the bridge's time per message, age = frame arrival to the DDS write.
  [[nodiscard]] const engine::GraphStats& stats() const noexcept { return stats_; }
  [[nodiscard]] DdsStatus dds_status() const { return ros_->status(); }
  [[nodiscard]] const BridgeTopics& topics() const noexcept { return ros_->topics(); }
  /// @brief The iceoryx side's counters, one line per topic (`ipc NAME TOPIC samples ...`).
  [[nodiscard]] std::string ipc_lines() const;

 private:
  BridgeLoop() = default;
  std::size_t pump_objects(std::int64_t now_ns);
  std::size_t pump_frame(std::int64_t now_ns);
  std::size_t pump_commands(std::int64_t now_ns);
  std::size_t pump_acks(std::int64_t now_ns);

  BridgeConfig config_;
  std::unique_ptr<RosEndpoints> ros_;
  std::unique_ptr<CommandRelay> relay_;
  std::unique_ptr<ArmStopRelay> arm_stop_;
  std::unique_ptr<engine::IpcSubscriber> objects_, frames_, acks_;
  std::unique_ptr<engine::IpcPublisher> commands_;
  std::unique_ptr<engine::ObjectListPayload> list_;  // aligned copy of the newest list
  std::int64_t last_frame_ns_ = 0;                   ///< the last frame taken (thinning)
  double frame_tokens_ = 1.0;  ///< frames that may go now (a bucket of 2 at max_frame_hz)
  std::int64_t start_ns_ = 0;
  BridgeCounters counters_;
  engine::GraphStats stats_;
  engine::NodeStats* objects_stats_ = nullptr;
  engine::NodeStats* points_stats_ = nullptr;
  engine::NodeStats* commands_stats_ = nullptr;
  engine::NodeStats* acks_stats_ = nullptr;
};

}  // namespace orthoflow::bridge
