#pragma once
/// @file
/// @brief (internal) What the `orthoflow arm ...` sub-commands share (cmd_arm.cpp: list, info,
/// state, stop; cmd_arm_motion.cpp: home, retract, move, fingers): their options, the transport
/// (libusb, or the simulated JACO with --sim), starting the arm, the limits from the options, and
/// the JSON of a snapshot.
#include <CLI/CLI.hpp>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "apps/commands.hpp"
#include "drivers/jaco/jaco_arm.hpp"
#include "drivers/usb/usb_transport.hpp"

namespace orthoflow::apps::arm_cli {

struct ArmArgs {
  bool sim = false;
  std::string sim_start = "home";   ///< noinit | home | retract | normal
  std::string sim_model = "jaco2";  ///< jaco2 | v1
  bool sim_never_init = false;
  std::string serial;
  bool json = false;
  bool follow = false;
  bool publish = false;               ///< state --follow: also on iceoryx orthoflow/jaco/state
  double seconds = 0.0;               ///< state --follow: 0 = until Ctrl-C
  double timeout_s = 60.0;            ///< motion commands: give up (and stop) after this
  std::string joints;                 ///< move --joints
  std::string pose;                   ///< move --pose
  double speed = 0.5;                 ///< fraction of the speed cap
  std::string fingers;                ///< fingers open | close | a,b,c
  std::vector<std::string> keep_out;  ///< x0,y0,z0,x1,y1,z1[,name]
  std::string workspace;              ///< x0,y0,z0,x1,y1,z1
};

/// @brief Prints "orthoflow arm: WHAT" on stderr and exits with @p code.
[[noreturn]] void fail(const std::string& what, int code = EXIT_FAILURE_GENERIC);
/// @brief The simulated arm (--sim, real time) or libusb.
[[nodiscard]] std::unique_ptr<drivers::UsbTransport> make_transport(const ArmArgs& a);
/// @brief The arm asked for (--serial, else the first one). Fails when there is none.
[[nodiscard]] drivers::UsbDeviceInfo find_arm(drivers::UsbTransport& t, const ArmArgs& a);
/// @brief Opens and starts the arm with the limits of the options and @p subscribers (run on the
/// arm's USB thread after every cycle).
[[nodiscard]] std::unique_ptr<drivers::jaco::JacoArm> start_arm(
    const ArmArgs& a, std::vector<drivers::jaco::StateCallback> subscribers = {});
/// @brief The snapshot as JSON (joints, pose, fingers, state, counters).
[[nodiscard]] nlohmann::json snapshot_json(const drivers::jaco::ArmSnapshot& s);
/// @brief A comma-separated list of exactly @p count finite numbers, or fail (EXIT_USAGE).
[[nodiscard]] std::vector<double> parse_numbers(const std::string& text, std::size_t count,
                                                const std::string& what);
/// @brief --sim, --sim-start, --sim-model, --serial, --json on @p sub.
void add_common_options(CLI::App* sub, const std::shared_ptr<ArmArgs>& a);
/// @brief home, retract, move, fingers under the arm command (cmd_arm_motion.cpp).
void add_motion_commands(CLI::App* arm, const std::shared_ptr<ArmArgs>& a);

}  // namespace orthoflow::apps::arm_cli
