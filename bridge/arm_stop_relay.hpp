#pragma once
/// @file
/// @brief The DDS bridge's arm stop (docs/SAFETY.md, docs/DDS.md): an ArmStop taken from DDS goes
/// to whatever process holds the arm, over iceoryx (engine/arm_stop_payload.hpp), and the holder's
/// acknowledgement comes back as an ArmStopAck; with no holder listening, or no answer within 2 s,
/// the ArmStopAck says so. Never blocks: one pass takes at most 16 stops and 16 acks, and at most
/// 16 stops wait for their answer (more are answered "busy" at once).
#include <array>
#include <cstdint>
#include <memory>
#include <string>

#include "bridge/ros_endpoints.hpp"
#include "core/result.hpp"
#include "engine/ipc_pubsub.hpp"

namespace orthoflow::bridge {

class ArmStopRelay {
 public:
  /// @pre the iceoryx runtime is initialised. @return iceoryx's refusal, named.
  [[nodiscard]] static Result<std::unique_ptr<ArmStopRelay>, std::string> open(
      const engine::IpcPools& pools);
  /// @brief One bounded pass at @p now_ns (steady clock). @return stops and acks handled.
  std::size_t pump(RosEndpoints& ros, std::int64_t now_ns);
  [[nodiscard]] std::uint64_t stops_in() const noexcept { return stops_in_; }
  [[nodiscard]] std::uint64_t stops_confirmed() const noexcept { return confirmed_; }

  static constexpr std::int64_t ANSWER_TIMEOUT_NS = 2'000'000'000;

 private:
  ArmStopRelay() = default;
  struct Pending {
    std::uint64_t id = 0;  ///< 0: free
    std::int64_t sent_ns = 0;
    std::array<char, 64> reason{};
  };
  void answer(RosEndpoints& ros, bool stopped, const Pending& p, const char* problem,
              bool was_moving = false, int holder_pid = 0, const char* holder = "",
              double ms = 0.0);

  std::unique_ptr<engine::IpcPublisher> requests_;
  std::unique_ptr<engine::IpcSubscriber> acks_;
  std::array<Pending, 16> pending_{};
  std::uint64_t next_id_ = 1;
  std::uint64_t stops_in_ = 0, confirmed_ = 0;
};

}  // namespace orthoflow::bridge
