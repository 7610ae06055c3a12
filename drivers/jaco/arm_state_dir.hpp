#pragma once
/// @file
/// @brief ArmStateDir: the arm's state directory (docs/SAFETY.md), which outlives the processes
/// that hold the arm:
/// - `holder`: the one process that holds the arm keeps an exclusive lock on this file and writes
///   its pid and what it is into it; a second process asking to hold the arm is refused, naming
///   the holder (the lock dies with the process, so a killed holder never blocks the next);
/// - `estop`: a latched stop, written atomically by whoever stopped the arm, with the reason and
///   the time. A process that takes the arm while it exists starts latched and refuses to move;
///   only `orthoflow arm reset` (a person) removes it.
/// The default place is $ORTHOFLOW_ARM_STATE_DIR, else /var/lib/orthoflow/arm where this user may
/// write there (the package's service user, root), else ~/.local/state/orthoflow/arm (a simulated
/// arm: $ORTHOFLOW_ARM_STATE_DIR/sim, else /tmp/orthoflow-sim-arm-<uid>, so a real and a simulated
/// arm never share a latch).
/// Not for the frame path: every call is a few system calls. Thread-safe: each call is
/// self-contained (the holder's lock lives in its ArmHold).
#include <optional>
#include <string>
#include <string_view>

#include "core/result.hpp"

namespace orthoflow::drivers::jaco {

/// @brief Who holds the arm.
struct ArmHolder {
  long pid = 0;
  std::string what;  ///< e.g. "orthoflow task run"
};

/// @brief A latched stop, as the file says.
struct ArmLatch {
  std::string reason;  ///< e.g. "SIGTERM", "orthoflow arm stop (pid 1234)", "web view"
  long pid = 0;        ///< the process that latched it
  long long unix_s = 0;
  bool was_moving = false;  ///< the arm was moving when it was stopped
};

/// @brief Holding the arm: the lock is released when this is destroyed (or the process ends).
/// Move-only.
class ArmHold {
 public:
  ArmHold() = default;
  ArmHold(ArmHold&& other) noexcept : fd_(other.fd_) { other.fd_ = -1; }
  ArmHold& operator=(ArmHold&& other) noexcept;
  ArmHold(const ArmHold&) = delete;
  ArmHold& operator=(const ArmHold&) = delete;
  ~ArmHold();
  [[nodiscard]] bool held() const noexcept { return fd_ >= 0; }

 private:
  friend class ArmStateDir;
  explicit ArmHold(int fd) noexcept : fd_(fd) {}
  int fd_ = -1;
};

class ArmStateDir {
 public:
  /// @brief The directory at @p path, created (mode 0700) if missing. @return a sentence on error.
  [[nodiscard]] static Result<ArmStateDir, std::string> open(std::string path);
  /// @brief The default path (see the file comment) for a real or a simulated arm. @pre none.
  [[nodiscard]] static std::string default_path(bool simulated);

  /// @brief Holds the arm as @p what. @return the holder's description when another process
  /// holds it ("held by pid 1234 (orthoflow task run)").
  [[nodiscard]] Result<ArmHold, std::string> hold(std::string_view what) const;
  /// @brief The process holding the arm now, if any. @pre none.
  [[nodiscard]] std::optional<ArmHolder> holder() const;
  /// @brief Writes the latch (atomically: a complete file or none). @pre none.
  [[nodiscard]] Result<void, std::string> latch(std::string_view reason,
                                                bool was_moving = false) const;
  /// @brief The latch, if one is set. @pre none.
  [[nodiscard]] std::optional<ArmLatch> latched() const;
  /// @brief Removes the latch (a person's reset). @pre none.
  [[nodiscard]] Result<void, std::string> clear_latch() const;
  [[nodiscard]] const std::string& path() const noexcept { return path_; }

 private:
  explicit ArmStateDir(std::string path) : path_(std::move(path)) {}
  std::string path_;
};

}  // namespace orthoflow::drivers::jaco
