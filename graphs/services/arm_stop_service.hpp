#pragma once
/// @file
/// @brief The arm's stop over iceoryx (engine/arm_stop_payload.hpp, docs/SAFETY.md): the process
/// holding the arm runs an ArmStopListener; anyone else (`orthoflow arm stop`, the web view's stop
/// button, the DDS bridge's stop topic) calls request_arm_stop and learns whether a holder halted
/// the arm, whether it was moving, and when. Not for the frame path: the listener has its own
/// thread (it polls every millisecond; it never touches the arm's control thread), the request
/// blocks its caller for at most its timeout.
#include <atomic>
#include <chrono>
#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <string_view>
#include <thread>

#include "core/result.hpp"
#include "engine/arm_stop_payload.hpp"
#include "engine/ipc_pubsub.hpp"

namespace orthoflow::graphs {

/// @brief In the process that holds the arm: answers every stop request once @p halt returned.
class ArmStopListener {
 public:
  /// Halts and latches the arm with @p reason; @return whether it was moving.
  using Halt = std::function<bool(std::string_view reason)>;
  /// @brief Subscribes to orthoflow/jaco/stop and offers orthoflow/jaco/stop_ack as @p holder.
  /// @pre the process's iceoryx runtime is up (engine::init_ipc_runtime). @return a sentence.
  [[nodiscard]] static Result<std::unique_ptr<ArmStopListener>, std::string> start(
      Halt halt, std::string holder);
  ~ArmStopListener();
  ArmStopListener(const ArmStopListener&) = delete;
  ArmStopListener& operator=(const ArmStopListener&) = delete;
  /// @brief Requests answered so far.
  [[nodiscard]] std::uint64_t served() const noexcept { return served_.load(); }

 private:
  ArmStopListener() = default;
  void run() noexcept;
  void serve(const engine::ArmStopRequest& request) noexcept;

  Halt halt_;
  std::string holder_;
  std::unique_ptr<engine::IpcSubscriber> requests_;
  std::unique_ptr<engine::IpcPublisher> acks_;
  std::atomic<bool> stop_{false};
  std::atomic<std::uint64_t> served_{0};
  std::thread thread_;
};

/// @brief What became of a stop request.
struct ArmStopOutcome {
  enum class Status : std::uint8_t {
    STOPPED,      ///< a holder halted and latched the arm and said so
    NO_LISTENER,  ///< nobody listens on orthoflow/jaco/stop: nothing was sent
    NO_ANSWER,    ///< sent, but no acknowledgement within the timeout
  };
  Status status = Status::NO_ANSWER;
  bool was_moving = false;
  int holder_pid = 0;
  std::string holder;
  std::int64_t request_ns = 0;  ///< this process's steady clock when it asked
  std::int64_t halted_ns = 0;   ///< the holder's steady clock when the arm was halted
};

/// @brief Asks the holder (@p target_pid, or any holder when 0) to stop the arm with @p reason and
/// waits up to @p timeout for its answer. @pre the iceoryx runtime is up. @return a sentence when
/// the topics cannot be created.
[[nodiscard]] Result<ArmStopOutcome, std::string> request_arm_stop(
    std::string_view reason, std::chrono::milliseconds timeout, int target_pid = 0);

/// @brief The steady clock (CLOCK_MONOTONIC) in ns, the clock stop requests are stamped with.
[[nodiscard]] std::int64_t steady_now_ns() noexcept;

}  // namespace orthoflow::graphs
