#pragma once
/// @file
/// @brief (internal) What the `orthoflow kinect ...` sub-commands share (cmd_kinect.cpp: list,
/// info, stream; cmd_kinect_motor.cpp: tilt, led, accel; cmd_kinect_record.cpp: record): their
/// options, the transport (libusb, or the simulated camera with --sim) and the error exit.
#include <CLI/CLI.hpp>
#include <cstdint>
#include <memory>
#include <string>

#include "apps/commands.hpp"
#include "drivers/usb/usb_transport.hpp"

namespace orthoflow::apps::kinect_cli {

struct KinectArgs {
  bool sim = false;
  std::string sim_model = "1414";
  double sim_drop = 0.0;
  std::string serial;
  bool json = false;
  std::uint64_t frames = 90;
  std::string tilt;  // text: the CLI-wide rule refuses negative numeric options (option_checks)
  bool wait = false;
  std::string led;
};

/// @brief Prints "orthoflow kinect: WHAT" on stderr and exits with @p code.
[[noreturn]] void fail(const std::string& what, int code = EXIT_FAILURE_GENERIC);
/// @brief The simulated camera (--sim: model, packet loss) or libusb.
[[nodiscard]] std::unique_ptr<drivers::UsbTransport> make_transport(const KinectArgs& a);
/// @brief --sim, --sim-model, --sim-drop, --json on @p sub.
void add_common_options(CLI::App* sub, const std::shared_ptr<KinectArgs>& a);
/// @brief tilt, led and accel under the kinect command (cmd_kinect_motor.cpp).
void add_motor_commands(CLI::App* kinect, const std::shared_ptr<KinectArgs>& a);

}  // namespace orthoflow::apps::kinect_cli
