#pragma once
/// @file
/// @brief The learning commands' way through the bridge (issue 23): a DDS sender's command becomes
/// a graph command from the bridge's own client id (so no DDS peer can pose as another iceoryx
/// client), and the graph's ack goes back to that sender's client and request. Bounded: at most
/// MAX_PENDING commands wait for their ack; more are answered QUEUE_FULL at once, and a command
/// unanswered past its deadline is answered TIMEOUT. No DDS or iceoryx here: pure bookkeeping.
#include <array>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>

#include "bridge/ros_messages.hpp"
#include "graphs/channels/learning_payloads.hpp"

namespace orthoflow::bridge {

/// @brief Where one graph ack goes back to.
struct AckRoute {
  std::uint64_t client = 0;   ///< the DDS sender's
  std::uint64_t request = 0;  ///< the DDS sender's
};

/// @brief What to do with one command from DDS.
struct RelayDecision {
  bool forward = false;  ///< publish `payload` to the graph
  graphs::LearningCommandPayload payload{};
  graphs::RemoteAck answer{};  ///< else: answer the sender at once with this
  std::string problem;         ///< ... and these words
  AckRoute route{};
  std::uint64_t bridge_request = 0;  ///< forwarded: the graph command's request id
};

class CommandRelay {
 public:
  static constexpr std::size_t MAX_PENDING = 256;

  /// @param client the bridge's iceoryx client id (non-zero, random per process)
  CommandRelay(std::uint64_t client, std::int64_t timeout_ns) noexcept
      : client_(client), timeout_ns_(timeout_ns) {}

  /// @brief A command from DDS at @p now_ns; @p graph_listening: the graph's command topic has a
  /// subscriber. Refused ones (from_ros) are answered INVALID; with no graph, TIMEOUT.
  [[nodiscard]] RelayDecision on_command(const RosLearningCommand& command, std::int64_t now_ns,
                                         bool graph_listening);
  /// @brief An ack on the graph's ack topic. @return where it goes, if it answers a pending
  /// command of this bridge (others are other clients' and ignored).
  [[nodiscard]] std::optional<AckRoute> on_ack(const graphs::RemoteAck& ack) noexcept;
  /// @brief The next pending command past its deadline at @p now_ns (removed), if any.
  [[nodiscard]] std::optional<AckRoute> next_expired(std::int64_t now_ns) noexcept;
  /// @brief Forgets the forwarded command @p bridge_request (it could not be sent).
  void cancel(std::uint64_t bridge_request) noexcept;
  [[nodiscard]] std::size_t pending() const noexcept { return pending_; }
  [[nodiscard]] std::uint64_t client() const noexcept { return client_; }

 private:
  struct Slot {
    bool used = false;
    std::uint64_t bridge_request = 0;
    AckRoute route{};
    std::int64_t deadline_ns = 0;
  };
  std::uint64_t client_;
  std::int64_t timeout_ns_;
  std::uint64_t next_request_ = 0;
  std::array<Slot, MAX_PENDING> slots_{};
  std::size_t pending_ = 0;
};

}  // namespace orthoflow::bridge
