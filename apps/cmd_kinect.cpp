// `orthoflow kinect list | info | stream | tilt | led | accel`: the Kinect v1 through orthoflow's
// own driver, for people at the robot. `--sim` runs the same commands on the simulated Kinect
// (simulation/devices/sim_usb_transport.hpp: the documented protocol; `stream` is paced to the wall
// clock, the motor runs on simulated time, so `tilt --wait` returns at once), so they can be tried,
// and are tested, on machines without USB. Each --sim run starts a fresh simulator: the head is
// level.
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <iostream>
#include <memory>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <thread>

#include "apps/commands.hpp"
#include "apps/kinect_cli.hpp"
#include "drivers/kinect/kinect_camera.hpp"
#include "drivers/kinect/kinect_depth.hpp"
#include "drivers/kinect/kinect_device.hpp"
#include "drivers/kinect/kinect_motor.hpp"
#include "drivers/usb/libusb_transport.hpp"
#include "simulation/devices/sim_usb_transport.hpp"

namespace orthoflow::apps {
namespace kinect_cli {

[[noreturn]] void fail(const std::string& what, int code) {
  std::cerr << "orthoflow kinect: " << what << '\n';
  throw CLI::RuntimeError(code);
}
std::unique_ptr<drivers::UsbTransport> make_transport(const KinectArgs& a) {
  if (a.sim) {
    simulation::SimKinectHostOptions sim;
    sim.model = a.sim_model == "1473"  ? simulation::KinectModel::K1473
                : a.sim_model == "k4w" ? simulation::KinectModel::K4W
                                       : simulation::KinectModel::K1414;
    sim.drop_rate = a.sim_drop;
    return simulation::make_sim_kinect_host(sim);
  }
  auto usb = drivers::LibusbTransport::create();
  if (!usb.has_value()) fail("cannot start libusb: " + drivers::to_string(usb.error()));
  return std::move(usb.value());
}

void add_common_options(CLI::App* sub, const std::shared_ptr<KinectArgs>& a) {
  sub->add_flag("--sim", a->sim, "use the simulated camera (no USB needed)");
  sub->add_option("--sim-model", a->sim_model, "simulated model: 1414, 1473 or k4w")
      ->check(CLI::IsMember({"1414", "1473", "k4w"}));
  sub->add_option("--sim-drop", a->sim_drop, "simulated packet loss rate")
      ->check(CLI::Range(0.0, 0.5));
  sub->add_flag("--json", a->json, "JSON output");
}

}  // namespace kinect_cli

namespace {

namespace kinect = drivers::kinect;
using namespace kinect_cli;

std::string port_path(const drivers::UsbDeviceInfo& d) {
  std::string s = std::to_string(d.bus) + "-";
  for (std::size_t i = 0; i < d.port_depth; ++i) {
    s += (i > 0 ? "." : "") + std::to_string(d.port_path[i]);
  }
  return s;
}

nlohmann::json camera_json(const kinect::CameraInfo& c) {
  return {{"model", kinect::to_string(c.model)},
          {"serial", std::string(c.serial.view())},
          {"bus", c.usb.bus},
          {"address", c.usb.address},
          {"port_path", port_path(c.usb)},
          {"bcd_device", c.usb.bcd_device},
          {"motor", c.has_motor}};
}

void run_list(const KinectArgs& a) {
  auto transport = make_transport(a);
  auto cameras = kinect::list_cameras(*transport);
  if (!cameras.has_value()) fail(kinect::to_string(cameras.error()));
  nlohmann::json out = nlohmann::json::array();
  for (const auto& c : cameras.value()) out.push_back(camera_json(c));
  if (a.json) {
    std::cout << out.dump(2) << '\n';
    return;
  }
  if (cameras.value().empty()) std::cout << "no Kinect v1 camera found\n";
  for (const auto& c : out) {
    std::cout << "kinect " << c["model"].get<std::string>() << "  serial "
              << c["serial"].get<std::string>() << "  bus path "
              << c["port_path"].get<std::string>() << (c["motor"].get<bool>() ? "  motor" : "")
              << '\n';
  }
}

std::unique_ptr<kinect::KinectCamera> open_camera(drivers::UsbTransport& t, const KinectArgs& a) {
  kinect::CameraOptions options;
  options.serial = a.serial;
  auto camera = kinect::KinectCamera::open(t, options);
  if (!camera.has_value()) {
    if (camera.error().code == kinect::KinectError::Code::NO_CAMERA)
      fail(a.serial.empty() ? "no Kinect v1 camera found" : "no camera with serial " + a.serial);
    fail("cannot open the camera: " + kinect::to_string(camera.error()));
  }
  return std::move(camera.value());
}

void run_info(const KinectArgs& a) {
  auto transport = make_transport(a);
  auto camera = open_camera(*transport, a);
  const kinect::Calibration& cal = camera->calibration();
  const kinect::DepthTableMm mm = kinect::make_depth_table_mm(cal);
  const kernels::DepthCamera pinhole = kinect::depth_camera(cal);
  nlohmann::json reg = nlohmann::json::object();
  for (std::size_t i = 0; i < cal.reg.words.size(); ++i)
    reg[kinect::reg_info_name(i)] = cal.reg.words[i];
  const nlohmann::json out = {
      {"camera", camera_json(camera->info())},
      {"zero_plane",
       {{"dcmos_emitter_distance", cal.zero_plane.dcmos_emitter_dist_cm},
        {"dcmos_rcmos_distance", cal.zero_plane.dcmos_rcmos_dist_cm},
        {"dcmos_rcmos_distance_reported", cal.reported_rcmos_dist_cm},
        {"reference_distance", cal.zero_plane.reference_distance_mm},
        {"reference_pixel_size", cal.zero_plane.reference_pixel_size_mm}}},
      {"pad_info",
       {{"start_lines", cal.pad.start_lines},
        {"end_lines", cal.pad.end_lines},
        {"cropping_lines", cal.pad.cropping_lines}}},
      {"const_shift", cal.const_shift},
      {"reg_info", reg},
      {"depth_camera",
       {{"fx", pinhole.fx}, {"fy", pinhole.fy}, {"cx", pinhole.cx}, {"cy", pinhole.cy}}},
      {"depth_mm_at_raw", {{"500", mm[500]}, {"800", mm[800]}, {"1000", mm[1000]}}},
      {"control",
       {{"commands", camera->control().stats().commands},
        {"retries", camera->control().stats().retries},
        {"not_ready_polls", camera->control().stats().not_ready_polls}}}};
  if (a.json) {
    std::cout << out.dump(2) << '\n';
    return;
  }
  const auto& c = out["camera"];
  std::cout << "kinect " << c["model"].get<std::string>() << ", serial "
            << c["serial"].get<std::string>() << ", bus path " << c["port_path"].get<std::string>()
            << '\n'
            << "zero plane: emitter " << cal.zero_plane.dcmos_emitter_dist_cm << " cm, distance "
            << cal.zero_plane.reference_distance_mm << " mm, pixel "
            << cal.zero_plane.reference_pixel_size_mm << " mm; const shift " << cal.const_shift
            << '\n'
            << "depth camera: f " << pinhole.fx << " px, c (" << pinhole.cx << ", " << pinhole.cy
            << "); raw 800 = " << mm[800] << " mm\n";
}

nlohmann::json health_json(const kinect::CameraHealth& h) {
  nlohmann::json out = nlohmann::json::object();
  for (const auto& c : kinect::health_counters(h)) out[c.name] = c.value;
  out["frames_whole"] = h.frames_delivered - h.frames_degraded;
  return out;
}

void run_stream(const KinectArgs& a) {
  kinect::DeviceOptions options;
  options.camera.serial = a.serial;
  options.pace_to_wall_clock = a.sim;
  auto device = kinect::KinectDevice::start(make_transport(a), options);
  if (!device.has_value()) fail("cannot start the camera: " + kinect::to_string(device.error()));
  kinect::KinectDevice& d = *device.value();
  std::uint64_t taken = 0;
  const auto start = std::chrono::steady_clock::now();
  auto next_line = start + std::chrono::seconds(1);
  // At most twice the expected time: a camera that stops delivering ends the command, not hangs it.
  const auto deadline =
      start + std::chrono::milliseconds(static_cast<std::int64_t>(a.frames) * 67 + 2000);
  double age_ms = 0.0;
  while (taken < a.frames && std::chrono::steady_clock::now() < deadline) {
    if (const kinect::DepthFrame* f = d.latest_depth()) {
      ++taken;
      age_ms = static_cast<double>(d.health().last_frame_host_ns - f->host_ns) / 1e6;
    }
    if (!a.json && std::chrono::steady_clock::now() >= next_line) {
      const auto h = d.health();
      std::cout << "frames " << h.frames_delivered << " (degraded " << h.frames_degraded
                << ", dropped " << h.frames_dropped << "), lost packets " << h.depth.lost_packets
                << ", resyncs " << h.depth.resyncs << ", restarts " << h.watchdog_restarts << '\n';
      next_line += std::chrono::seconds(1);
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(2));
  }
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  nlohmann::json out = health_json(d.health());
  out["frames_taken"] = taken;
  out["seconds"] = seconds;
  out["fps"] = static_cast<double>(taken) / seconds;
  out["last_age_ms"] = age_ms;
  if (a.json) {
    std::cout << out.dump(2) << '\n';
  } else {
    std::cout << "took " << taken << " frames in " << seconds << " s (" << out["fps"].get<double>()
              << " Hz); whole " << out["frames_whole"] << ", degraded " << out["frames_degraded"]
              << ", dropped " << out["frames_dropped"] << '\n';
  }
  if (taken < a.frames)
    fail("the camera delivered " + std::to_string(taken) + " of " + std::to_string(a.frames) +
         " frames in time");
}

}  // namespace

void add_kinect_command(CLI::App& app) {
  auto* cmd = app.add_subcommand(
      "kinect", "the Kinect v1 through orthoflow's driver: list, info, stream, tilt, led, accel");
  cmd->require_subcommand(1);
  auto a = std::make_shared<kinect_cli::KinectArgs>();
  auto common = [a](CLI::App* sub) { kinect_cli::add_common_options(sub, a); };

  auto* list = cmd->add_subcommand("list", "the Kinect v1 cameras present");
  common(list);
  list->callback([a] { run_list(*a); });
  auto* info = cmd->add_subcommand("info", "model, serial, bus path and calibration of a camera");
  common(info);
  info->add_option("--serial", a->serial, "which camera (default: the first)");
  info->callback([a] { run_info(*a); });
  auto* stream = cmd->add_subcommand("stream", "stream depth and report the driver's health");
  common(stream);
  stream->add_option("--serial", a->serial, "which camera (default: the first)");
  stream->add_option("--frames", a->frames, "frames to take (default 90)")
      ->check(CLI::Range(1, 1'000'000));
  stream->callback([a] { run_stream(*a); });
  kinect_cli::add_motor_commands(cmd, a);
}

}  // namespace orthoflow::apps
