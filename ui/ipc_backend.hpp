#pragma once
/// @file
/// @brief IpcBackend: the web view's backend over a graph running in another process (`orthoflow
/// ui`, beside `orthoflow run --ipc-learning`). Objects come from the iceoryx topic
/// orthoflow/<graph>/objects, the memory and telemetry from .../status, and actions go out on
/// .../learning_commands and come back on .../learning_acks
/// (graphs/channels/learning_payloads.hpp). A thread here takes every topic; state older than
/// STALE_AFTER_NS is not shown (a graph that stopped shows no objects to click). No camera image:
/// frames do not cross to this process.
#include <atomic>
#include <condition_variable>
#include <cstdint>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>

#include "core/result.hpp"
#include "engine/object_list_payload.hpp"
#include "graphs/channels/learning_payloads.hpp"
#include "ui/backend_support.hpp"
#include "ui/ui_backend.hpp"

namespace orthoflow::engine {
class IpcPublisher;
class IpcSubscriber;
}  // namespace orthoflow::engine

namespace orthoflow::ui {

/// @brief Objects or status older than this (by arrival) are dropped from the page.
inline constexpr std::int64_t STALE_AFTER_NS = 2'000'000'000;

/// @brief What the backend took and refused, readable from any thread.
struct IpcBackendCounters {
  std::atomic<std::uint64_t> object_lists{0}, statuses{0}, acks{0};
  std::atomic<std::uint64_t> rejected{0};  ///< payloads that failed decoding (never shown)
};

/// @note Thread-safe.
class IpcBackend final : public UiBackend {
 public:
  /// @brief Subscribes to graph @p graph's topics and offers its command topic. @pre the process's
  /// iceoryx runtime is initialised. Errors: iceoryx refused, RouDi's pools lack a chunk.
  [[nodiscard]] static Result<std::unique_ptr<IpcBackend>, std::string> open(
      const std::string& graph);
  ~IpcBackend() override;
  IpcBackend(const IpcBackend&) = delete;
  IpcBackend& operator=(const IpcBackend&) = delete;

  [[nodiscard]] UiSnapshot snapshot() const override;
  /// @brief TIMEOUT at once when no graph takes commands; a command the graph's bridge refused as
  /// invalid comes back ACKNOWLEDGED with outcome BAD_LABEL.
  [[nodiscard]] UiAnswer submit(const UiAction& action, int timeout_ms) override;
  [[nodiscard]] bool durable() const noexcept override { return durable_.load(); }
  /// @brief Whether a graph's status arrived within STALE_AFTER_NS.
  [[nodiscard]] bool connected() const;
  [[nodiscard]] const IpcBackendCounters& counters() const noexcept { return counters_; }

 private:
  IpcBackend(std::unique_ptr<engine::IpcSubscriber> objects,
             std::unique_ptr<engine::IpcSubscriber> status,
             std::unique_ptr<engine::IpcSubscriber> acks,
             std::unique_ptr<engine::IpcPublisher> commands);
  void poll() noexcept;
  void take_objects();
  void take_status();
  void take_acks();

  std::unique_ptr<engine::IpcSubscriber> objects_in_;
  std::unique_ptr<engine::IpcSubscriber> status_in_;
  std::unique_ptr<engine::IpcSubscriber> acks_in_;
  std::unique_ptr<engine::IpcPublisher> commands_out_;  // guarded by send_lock_
  std::mutex send_lock_;
  std::uint64_t client_id_ = 0;     // random per backend: acks for others are skipped
  std::uint64_t next_request_ = 1;  // guarded by send_lock_
  mutable std::mutex state_lock_;
  std::unique_ptr<engine::ObjectListPayload> latest_;  // guarded by state_lock_
  std::int64_t objects_at_ns_ = 0;                     // guarded by state_lock_: arrival
  graphs::RemoteStatus status_;                        // guarded by state_lock_
  std::int64_t status_at_ns_ = 0;                      // guarded by state_lock_: arrival
  // Requests a submit() waits for, and their answers once here (late answers are not kept).
  std::map<std::uint64_t, std::optional<graphs::RemoteAck>> awaited_;  // guarded by state_lock_
  std::condition_variable answered_;
  std::atomic<bool> durable_{false};
  EventLog events_;
  IpcBackendCounters counters_;
  std::atomic<bool> stop_{false};
  std::thread poller_;
};

}  // namespace orthoflow::ui
