#pragma once
/// @file
/// @brief (internal) What the `orthoflow arm ...` sub-commands share (cmd_arm.cpp: list, info,
/// state, stop; cmd_arm_motion.cpp: home, retract, move, fingers): their options, the transport
/// (libusb, or the simulated JACO with --sim), starting the arm, the limits from the options, and
/// the JSON of a snapshot.
#include <CLI/CLI.hpp>
#include <memory>
#include <optional>

#include <Eigen/Geometry>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "apps/commands.hpp"
#include "drivers/jaco/jaco_arm.hpp"
#include "drivers/usb/usb_transport.hpp"
#include "graphs/services/arm_stop_service.hpp"
#include "manipulation/arm_limits_file.hpp"

namespace orthoflow::apps::arm_cli {

struct ArmArgs {
  bool sim = false;
  std::string sim_start = "home";   ///< noinit | home | retract | normal
  std::string sim_model = "jaco2";  ///< jaco2 | v1
  bool sim_never_init = false;
  std::string serial;
  bool json = false;
  bool follow = false;
  bool publish = false;                ///< state --follow: also on iceoryx orthoflow/jaco/state
  double seconds = 0.0;                ///< state --follow: 0 = until Ctrl-C
  double timeout_s = 60.0;             ///< motion commands: give up (and stop) after this
  std::string joints;                  ///< move --joints
  std::string pose;                    ///< move --pose
  double speed = 0.5;                  ///< fraction of the speed cap
  std::string fingers;                 ///< fingers open | close | a,b,c
  std::vector<std::string> keep_out;   ///< x0,y0,z0,x1,y1,z1[,name]
  std::string workspace;               ///< x0,y0,z0,x1,y1,z1
  std::string limits;                  ///< --limits FILE (default: DEFAULT_LIMITS_PATH if present)
  std::string state_dir;               ///< --state-dir (default: ArmStateDir::default_path)
  std::string frames;                  ///< --frames: place the camera's keep-out
  std::string what = "orthoflow arm";  ///< what the holder file says this process is
  /// The camera's pose in the base frame, when the command knows it (task run): its keep-out.
  std::optional<Eigen::Isometry3d> base_from_camera;
  bool motion = false;  ///< the command moves the arm: signals halt and latch it
};

/// @brief Where the limits file is read from when --limits is not given (if it exists).
inline constexpr const char* DEFAULT_LIMITS_PATH = "/etc/orthoflow/arm_limits.yaml";

/// @brief The arm with what holds it: the stop listener (when RouDi runs) goes first.
struct HeldArm {
  std::unique_ptr<drivers::jaco::JacoArm> arm;
  std::unique_ptr<graphs::ArmStopListener> stop_listener;  ///< destroyed before the arm
  drivers::jaco::JacoArm* operator->() const noexcept { return arm.get(); }
  drivers::jaco::JacoArm& operator*() const noexcept { return *arm; }
  void reset() noexcept {
    stop_listener.reset();
    arm.reset();
  }
};

/// @brief Prints "orthoflow arm: WHAT" on stderr and exits with @p code.
[[noreturn]] void fail(const std::string& what, int code = EXIT_FAILURE_GENERIC);
/// @brief The simulated arm (--sim, real time) or libusb.
[[nodiscard]] std::unique_ptr<drivers::UsbTransport> make_transport(const ArmArgs& a);
/// @brief The arm asked for (--serial, else the first one). Fails when there is none.
[[nodiscard]] drivers::UsbDeviceInfo find_arm(drivers::UsbTransport& t, const ArmArgs& a);
/// @brief The limits: --limits, else DEFAULT_LIMITS_PATH if it exists, else the built-in
/// defaults; then --workspace and --keep-out; the camera's keep-out when its pose is known.
/// Fails (EXIT_USAGE / EXIT_BAD_INPUT) naming the key or option.
[[nodiscard]] manipulation::ArmLimitsFile load_limits(const ArmArgs& a);
/// @brief Holds and opens the arm with load_limits(a) and @p subscribers (run on the arm's notifier
/// thread after every cycle); a motion command installs the stop signals (a signal halts the arm
/// in place and latches it) and refuses a latched arm; with RouDi running, it also answers stop
/// requests over iceoryx (graphs/services/arm_stop_service.hpp).
[[nodiscard]] HeldArm start_arm(const ArmArgs& a,
                                std::vector<drivers::jaco::StateCallback> subscribers = {});
/// @brief The state directory of --state-dir, or the default one. @pre none.
[[nodiscard]] std::string state_dir_path(const ArmArgs& a);
/// @brief The snapshot as JSON (joints, pose, fingers, state, counters).
[[nodiscard]] nlohmann::json snapshot_json(const drivers::jaco::ArmSnapshot& s);
/// @brief A comma-separated list of exactly @p count finite numbers, or fail (EXIT_USAGE).
[[nodiscard]] std::vector<double> parse_numbers(const std::string& text, std::size_t count,
                                                const std::string& what);
/// @brief --sim, --sim-start, --sim-model, --serial, --json, --limits, --state-dir on @p sub.
void add_common_options(CLI::App* sub, const std::shared_ptr<ArmArgs>& a);
/// @brief home, retract, move, fingers under the arm command (cmd_arm_motion.cpp).
void add_motion_commands(CLI::App* arm, const std::shared_ptr<ArmArgs>& a);
/// @brief stop, reset, limits under the arm command (cmd_arm_safety.cpp).
void add_safety_commands(CLI::App* arm, const std::shared_ptr<ArmArgs>& a);

}  // namespace orthoflow::apps::arm_cli
