#pragma once
/// @file
/// @brief LearningIpcBridge: the learning channel of a running graph, reachable from other
/// processes over iceoryx (`orthoflow run --ipc-learning`; graphs/channels/learning_payloads.hpp
/// has the topics and payloads). A thread of its own (never the frame path) takes commands from
/// orthoflow/<graph>/learning_commands, validates them as the teaching UI's API does, sends them
/// through one LearningClient, and publishes every answer on .../learning_acks; it publishes the
/// memory's categories and the engine's telemetry on .../status five times a second.
///
/// Who may send: any process that may attach to this RouDi's shared memory (the same user, or the
/// group RouDi grants): the same trust as the graph's own processes (docs/IPC.md).
#include <atomic>
#include <cstdint>
#include <memory>
#include <string>
#include <thread>

#include "core/result.hpp"
#include "engine/ipc_pubsub.hpp"
#include "engine/telemetry.hpp"
#include "graphs/services/learning_service.hpp"

namespace orthoflow::graphs {

/// @brief The iceoryx topics a graph run with --ipc-learning offers: orthoflow/<graph>/objects,
/// the learning_payloads.hpp topics. The one place both ends (this bridge and ui::IpcBackend) name
/// them.
struct GraphTopics {
  engine::IpcTopic objects, commands, acks, status;
  engine::IpcTopic frames;  ///< `orthoflow run --publish-frames` (the DDS bridge reads it)
};
/// @brief The topics of graph @p graph. Errors: @p graph is not a topic name part (1..100 of
/// [A-Za-z0-9_.-]).
[[nodiscard]] Result<GraphTopics, std::string> graph_topics(const std::string& graph);

/// @brief What the bridge did, readable from any thread.
struct LearningIpcCounters {
  std::atomic<std::uint64_t> commands{0};  ///< taken from the topic
  std::atomic<std::uint64_t> invalid{0};   ///< refused by validation (an INVALID ack went back)
  std::atomic<std::uint64_t> acks{0};      ///< answers published
  std::atomic<std::uint64_t> timeouts{0};  ///< commands the graph did not answer within 5 s
  std::atomic<std::uint64_t> statuses{0};  ///< status payloads published
};

/// @pre destroyed before @p learning and @p stats.
class LearningIpcBridge {
 public:
  /// @brief Offers the ack and status topics and subscribes to the command topic of graph
  /// @p graph. @pre the process's iceoryx runtime is initialised (an IPC node was built).
  /// Errors: no free learning client slot, RouDi's pools lack a 16 KiB chunk, iceoryx refused.
  [[nodiscard]] static Result<std::unique_ptr<LearningIpcBridge>, std::string> open(
      const std::string& graph, LearningService& learning, const engine::GraphStats& stats);
  ~LearningIpcBridge();
  LearningIpcBridge(const LearningIpcBridge&) = delete;
  LearningIpcBridge& operator=(const LearningIpcBridge&) = delete;

  [[nodiscard]] const LearningIpcCounters& counters() const noexcept { return counters_; }

 private:
  struct Pending;
  LearningIpcBridge(LearningService& learning, const engine::GraphStats& stats,
                    std::unique_ptr<LearningClient> client,
                    std::unique_ptr<engine::IpcSubscriber> commands,
                    std::unique_ptr<engine::IpcPublisher> acks,
                    std::unique_ptr<engine::IpcPublisher> status);
  void loop() noexcept;

  LearningService& learning_;
  const engine::GraphStats& stats_;
  std::unique_ptr<LearningClient> client_;
  std::unique_ptr<engine::IpcSubscriber> commands_;
  std::unique_ptr<engine::IpcPublisher> acks_;
  std::unique_ptr<engine::IpcPublisher> status_;
  LearningIpcCounters counters_;
  std::atomic<bool> stop_{false};
  std::thread thread_;
};

}  // namespace orthoflow::graphs
