#pragma once
/// @file
/// @brief Where the robot-body filter (graphs/nodes/body_filter_node.hpp) reads the arm's joint
/// states: engine::ArmStatePayload samples, either from the iceoryx topic `orthoflow/jaco/state`
/// (what `orthoflow arm state --follow --publish` sends at the arm's 100 Hz) or from an
/// ArmStateChannel that an arm in the same process (the simulated JACO of a closed-loop run, a
/// test) writes. The filter keeps a short history of them and looks up the arm at each frame's
/// time, as a transform buffer does. Reading never blocks and never allocates.
#include <array>
#include <atomic>
#include <cstdint>
#include <memory>
#include <span>
#include <string>

#include "core/result.hpp"
#include "drivers/jaco/jaco_controller.hpp"
#include "engine/arm_state_payload.hpp"
#include "engine/ipc_pubsub.hpp"
#include "manipulation/arm_body.hpp"

namespace orthoflow::graphs {

/// @brief The arm-state sample of snapshot @p s stamped @p stamp_ns (the clock of the frames), with
/// what the hand holds (@p held, none by default) for the body filter. No allocation.
[[nodiscard]] engine::ArmStatePayload arm_state_payload(
    const drivers::jaco::ArmSnapshot& s, std::int64_t stamp_ns,
    const manipulation::HeldObject& held = {}) noexcept;

/// @brief Arm states as they arrive.
class ArmStateFeed {
 public:
  virtual ~ArmStateFeed() = default;
  /// @brief The states that arrived since the previous call, oldest first, into @p out: at most
  /// out.size() of them (the newest, if more came). @return how many.
  /// @note One reader thread (the body filter is a serial node); no allocation, never blocks, a
  /// bounded amount of work.
  [[nodiscard]] virtual std::size_t drain(std::span<engine::ArmStatePayload> out) noexcept = 0;
  /// @brief States received so far (a publisher's samples, or a channel's writes).
  [[nodiscard]] virtual std::uint64_t received() const noexcept = 0;
  /// @brief Samples refused for a wrong type, version or size (the IPC feed; a channel has none).
  [[nodiscard]] virtual std::uint64_t rejected() const noexcept { return 0; }
};

/// @brief Arm states shared in-process: one writer thread, one reader thread, lock-free; the last
/// DEPTH writes are kept (a ring of sequence-locked entries over relaxed atomic words, so it is
/// race-free by the memory model too).
class ArmStateChannel final : public ArmStateFeed {
 public:
  static constexpr std::size_t DEPTH = 64;
  /// @brief Publishes @p state (the writer: an arm's control loop). No allocation.
  void write(const engine::ArmStatePayload& state) noexcept;
  std::size_t drain(std::span<engine::ArmStatePayload> out) noexcept override;
  std::uint64_t received() const noexcept override {
    return written_.load(std::memory_order_relaxed);
  }

 private:
  static constexpr std::size_t WORDS = sizeof(engine::ArmStatePayload) / sizeof(std::uint64_t);
  static_assert(sizeof(engine::ArmStatePayload) % sizeof(std::uint64_t) == 0);
  struct Entry {
    std::atomic<std::uint64_t> sequence{0};  ///< 2n + 1 while write n is under way, 2n + 2 after
    std::array<std::atomic<std::uint64_t>, WORDS> words{};
  };
  std::array<Entry, DEPTH> entries_{};
  std::atomic<std::uint64_t> written_{0};
  std::uint64_t read_ = 0;  ///< the reader's: writes before this one were drained
};

/// @brief The arm states of an iceoryx topic (a FIFO subscriber of depth 64: 640 ms at 100 Hz).
class IpcArmStateFeed final : public ArmStateFeed {
 public:
  /// @brief Subscribes to @p topic (`service/instance/event`). @pre the process's iceoryx runtime
  /// is initialised. Start-up only (allocates). @return the reason it cannot.
  [[nodiscard]] static Result<std::unique_ptr<IpcArmStateFeed>, std::string> create(
      const std::string& topic);
  std::size_t drain(std::span<engine::ArmStatePayload> out) noexcept override;
  std::uint64_t received() const noexcept override;
  std::uint64_t rejected() const noexcept override;

 private:
  explicit IpcArmStateFeed(std::unique_ptr<engine::IpcSubscriber> subscriber) noexcept
      : subscriber_(std::move(subscriber)) {}
  std::unique_ptr<engine::IpcSubscriber> subscriber_;
};

}  // namespace orthoflow::graphs
