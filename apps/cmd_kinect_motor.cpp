// `orthoflow kinect tilt DEGREES [--wait] | led MODE | accel`: the model-1414 motor, LED and
// accelerometer through orthoflow's driver (drivers/kinect_motor.hpp); --sim runs them on the
// simulated motor.
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <iostream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>

#include "apps/kinect_cli.hpp"
#include "drivers/kinect_camera.hpp"
#include "drivers/kinect_motor.hpp"

namespace orthoflow::apps::kinect_cli {
namespace {

namespace kinect = drivers::kinect;

// ---- kinect tilt | led | accel: the 1414 motor function (drivers/kinect_motor.hpp) ----

kinect::CameraInfo find_camera(drivers::UsbTransport& t, const KinectArgs& a) {
  auto cameras = kinect::list_cameras(t);
  if (!cameras.has_value()) fail(kinect::to_string(cameras.error()));
  for (const auto& c : cameras.value()) {
    if (a.serial.empty() || c.serial.view() == a.serial) return c;
  }
  fail(a.serial.empty() ? "no Kinect v1 camera found" : "no camera with serial " + a.serial);
}

std::unique_ptr<kinect::KinectMotor> open_motor(drivers::UsbTransport& t, const KinectArgs& a) {
  auto motor = kinect::KinectMotor::open(t, find_camera(t, a));
  if (!motor.has_value()) fail("cannot open the motor: " + kinect::to_string(motor.error()));
  return std::move(motor.value());
}

std::string text(double v) {
  std::ostringstream out;
  out << v;
  return out.str();
}

void print_state(const kinect::MotorState& s, bool json) {
  const nlohmann::json tilt = s.tilt_deg ? nlohmann::json(*s.tilt_deg) : nlohmann::json(nullptr);
  const nlohmann::json out = {{"tilt_deg", tilt},           {"status", kinect::to_string(s.status)},
                              {"status_raw", s.status_raw}, {"accel_g", s.accel_g},
                              {"accel_mps2", s.accel_mps2}, {"accel_counts", s.accel_counts}};
  if (json) {
    std::cout << out.dump(2) << '\n';
    return;
  }
  std::cout << "tilt " << (s.tilt_deg ? text(*s.tilt_deg) : "unknown") << " deg, "
            << kinect::to_string(s.status) << "; accel " << s.accel_g[0] << ' ' << s.accel_g[1]
            << ' ' << s.accel_g[2] << " g\n";
}

void run_tilt(const KinectArgs& a) {
  char* end = nullptr;
  const double degrees = std::strtod(a.tilt.c_str(), &end);
  if (a.tilt.empty() || end != a.tilt.c_str() + a.tilt.size() || !std::isfinite(degrees))
    fail("tilt '" + a.tilt + "' is not a finite number of degrees", EXIT_USAGE);
  auto transport = make_transport(a);
  auto motor = open_motor(*transport, a);
  if (auto sent = motor->set_tilt(degrees); !sent.has_value()) {
    if (sent.error().code == kinect::KinectError::Code::INVALID_ARGUMENT)
      fail("tilt " + a.tilt + " is beyond the motor's limit of +-" +
               text(kinect::MOTOR_TILT_LIMIT_DEG) + " degrees (refused, not clipped)",
           EXIT_USAGE);
    fail("cannot tilt: " + kinect::to_string(sent.error()));
  }
  auto state = a.wait ? motor->wait_until_still(std::chrono::seconds(10)) : motor->read_state();
  if (!state.has_value()) fail("cannot read the motor state: " + kinect::to_string(state.error()));
  print_state(state.value(), a.json);
  // KINECT_V1.md 13, row 13: an unknown status (a book lists 0x08 = stall) is an error.
  if (a.wait && state.value().status == kinect::TiltStatus::UNKNOWN)
    fail("the motor stopped with unknown status " + std::to_string(state.value().status_raw));
}

void run_led(const KinectArgs& a) {
  auto transport = make_transport(a);
  auto motor = open_motor(*transport, a);
  const auto mode = kinect::parse_led_mode(a.led);
  if (!mode) fail("unknown LED mode " + a.led, EXIT_USAGE);  // CLI11 checked it already
  if (auto set = motor->set_led(*mode); !set.has_value())
    fail("cannot set the LED: " + kinect::to_string(set.error()));
  if (a.json) {
    std::cout << nlohmann::json{{"led", kinect::to_string(*mode)}}.dump(2) << '\n';
  } else {
    std::cout << "led " << kinect::to_string(*mode) << '\n';
  }
}

void run_accel(const KinectArgs& a) {
  auto transport = make_transport(a);
  auto motor = open_motor(*transport, a);
  auto state = motor->read_state();
  if (!state.has_value()) fail("cannot read the motor state: " + kinect::to_string(state.error()));
  print_state(state.value(), a.json);
}

}  // namespace

void add_motor_commands(CLI::App* cmd, const std::shared_ptr<KinectArgs>& a) {
  auto common = [a](CLI::App* sub) { add_common_options(sub, a); };
  auto* tilt = cmd->add_subcommand("tilt", "tilt the head (1414 motor), degrees from the horizon");
  common(tilt);
  tilt->add_option("--serial", a->serial, "which Kinect (default: the first)");
  tilt->add_option("degrees", a->tilt, "target angle, -31 to 31 (half-degree steps)")
      ->type_name("DEGREES")
      ->required();
  tilt->add_flag("--wait", a->wait, "wait (up to 10 s) until the motor stops, then report");
  tilt->callback([a] { run_tilt(*a); });
  auto* led = cmd->add_subcommand("led", "set the LED (1414 motor function)");
  common(led);
  led->add_option("--serial", a->serial, "which Kinect (default: the first)");
  led->add_option("mode", a->led,
                  "off, green, red, yellow; blink-green, blink-red-yellow (uncertain)")
      ->required()
      ->check(CLI::IsMember({"off", "green", "red", "yellow", "blink-green", "blink-red-yellow"}));
  led->callback([a] { run_led(*a); });
  auto* accel = cmd->add_subcommand("accel", "tilt, motor status and accelerometer (in g)");
  common(accel);
  accel->add_option("--serial", a->serial, "which Kinect (default: the first)");
  accel->callback([a] { run_accel(*a); });
}

}  // namespace orthoflow::apps::kinect_cli
