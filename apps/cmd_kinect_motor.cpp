// `orthoflow kinect tilt DEGREES [--wait] | led MODE | accel`: the motor, LED and accelerometer
// through orthoflow's driver (drivers/kinect/kinect_motor.hpp: the 1414 motor function, or on a
// 1473 / K4W the running audio firmware); --sim runs them on the simulated Kinect. `orthoflow
// kinect firmware [--file PATH]`: uploads the audio firmware of a 1473 / K4W
// (drivers/kinect/kinect_audio.hpp). Without --file, audios.bin is searched in libfreenect's order.
// The file is not redistributable and not shipped. With --sim the simulated Kinect (--sim-model
// 1473 or k4w) accepts any image with a valid header, so --file must name a synthetic image; the
// simulated upload lives only as long as the command (a later `kinect tilt --sim` starts afresh).
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <iostream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>

#include "apps/kinect_cli.hpp"
#include "drivers/kinect/kinect_audio.hpp"
#include "drivers/kinect/kinect_camera.hpp"
#include "drivers/kinect/kinect_motor.hpp"

namespace orthoflow::apps::kinect_cli {
namespace {

namespace kinect = drivers::kinect;

// ---- kinect tilt | led | accel: the 1414 motor function (drivers/kinect/kinect_motor.hpp) ----

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

// ---- kinect firmware: the 1473 / K4W audio firmware upload (drivers/kinect/kinect_audio.hpp) ----

std::string find_firmware_file(const std::string& given) {
  if (!given.empty()) return given;
  for (const std::string& dir : kinect::firmware_search_paths()) {
    const std::filesystem::path candidate =
        std::filesystem::path(dir) / std::string(kinect::AUDIO_FIRMWARE_FILE);
    std::error_code ec;
    if (std::filesystem::is_regular_file(candidate, ec)) return candidate.string();
  }
  std::string where;
  for (const std::string& dir : kinect::firmware_search_paths()) where += " " + dir;
  fail("no audios.bin found (searched:" + where +
           "); extract it with libfreenect's fwfetcher.py and pass --file PATH",
       EXIT_USAGE);
}

void run_firmware(const KinectArgs& a, const std::string& file) {
  const std::string path = find_firmware_file(file);
  auto image = kinect::read_firmware_file(path);
  if (!image.has_value()) fail("cannot read " + path + ": " + kinect::to_string(image.error()));
  auto transport = make_transport(a);
  kinect::FirmwareLoader loader(*transport);
  auto audio = loader.find_audio(find_camera(*transport, a));
  if (!audio.has_value()) fail("cannot find the audio device: " + kinect::to_string(audio.error()));
  const bool was_running =
      kinect::audio_firmware_state(audio.value()) == kinect::AudioFirmware::RUNNING;
  auto running = loader.upload(audio.value(), image.value());
  if (!running.has_value())
    fail("audio firmware upload failed: " + kinect::to_string(running.error()));
  const drivers::UsbDeviceInfo& d = running.value();
  const char* state = was_running ? "already_running" : "uploaded";
  if (a.json) {
    const nlohmann::json out = {{"state", state},
                                {"file", path},
                                {"bus", d.bus},
                                {"address", d.address},
                                {"interfaces", d.interface_count},
                                {"serial", std::string(d.serial.view())},
                                {"chunks", loader.stats().chunks},
                                {"bytes", loader.stats().bytes}};
    std::cout << out.dump(2) << '\n';
    return;
  }
  std::cout << "audio firmware " << state << " (" << loader.stats().bytes << " bytes in "
            << loader.stats().chunks << " chunks); audio device " << int{d.bus} << ':'
            << int{d.address} << ", " << int{d.interface_count} << " interfaces\n";
}

}  // namespace

void add_motor_commands(CLI::App* cmd, const std::shared_ptr<KinectArgs>& a) {
  auto common = [a](CLI::App* sub) { add_common_options(sub, a); };
  auto* tilt = cmd->add_subcommand(
      "tilt",
      "tilt the head (1414 motor; 1473 / K4W after kinect firmware), degrees from the horizon");
  common(tilt);
  tilt->add_option("--serial", a->serial, "which Kinect (default: the first)");
  tilt->add_option("degrees", a->tilt, "target angle, -31 to 31 (half-degree steps)")
      ->type_name("DEGREES")
      ->required();
  tilt->add_flag("--wait", a->wait, "wait (up to 10 s) until the motor stops, then report");
  tilt->callback([a] { run_tilt(*a); });
  auto* led = cmd->add_subcommand(
      "led", "set the LED (1414 motor function; 1473 / K4W after kinect firmware)");
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
  auto file = std::make_shared<std::string>();
  auto* firmware = cmd->add_subcommand(
      "firmware", "upload the 1473 / K4W audio firmware (needed before tilt, led, accel)");
  common(firmware);
  firmware->add_option("--serial", a->serial, "which Kinect (default: the first)");
  firmware->add_option("--file", *file,
                       "audios.bin (default: searched as libfreenect does; with --sim: a "
                       "synthetic image with a valid header)");
  firmware->callback([a, file] { run_firmware(*a, *file); });
}

}  // namespace orthoflow::apps::kinect_cli
