// `orthoflow kinect record DIR`: records the camera in libfreenect's fakenect format (INDEX.txt,
// d-*.pgm raw 11-bit depth, r-*.ppm demosaiced colour, device.json with the device's registration
// parameters: formats/fakenect.hpp), so recordings move both ways between orthoflow and
// libfreenect's fakenect tools; `orthoflow run --source replay:DIR` replays them. Like
// fakenect-record it refuses a directory that already holds a recording.
#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <memory>
#include <string>
#include <thread>
#include <vector>

#include "apps/commands.hpp"
#include "apps/kinect_cli.hpp"
#include "drivers/kinect/kinect_device.hpp"
#include "formats/fakenect.hpp"
#include "graphs/nodes/fakenect_calibration.hpp"
#include "kernels/bayer_demosaic.hpp"

namespace orthoflow::apps {
namespace {

namespace kinect = drivers::kinect;

struct RecordArgs {
  std::string dir;
  bool sim = false;
  double sim_drop = 0.0;
  std::string serial;
  std::uint64_t frames = 90;
  bool no_colour = false;
};

[[noreturn]] void fail(const std::string& what, int code = EXIT_FAILURE_GENERIC) {
  kinect_cli::fail("record: " + what, code);
}

double wall_seconds() {
  return std::chrono::duration<double>(std::chrono::system_clock::now().time_since_epoch()).count();
}

void record(const RecordArgs& a) {
  const std::filesystem::path dir(a.dir);
  if (std::filesystem::exists(dir / "INDEX.txt"))
    fail(a.dir + " already holds a recording (INDEX.txt): choose a new directory", EXIT_USAGE);
  std::error_code ec;
  std::filesystem::create_directories(dir, ec);
  if (ec) fail("cannot create " + a.dir + ": " + ec.message());

  kinect_cli::KinectArgs transport_args;
  transport_args.sim = a.sim;
  transport_args.sim_drop = a.sim_drop;
  auto transport = kinect_cli::make_transport(transport_args);
  kinect::DeviceOptions options;
  options.camera.serial = a.serial;
  options.camera.colour = !a.no_colour;
  options.pace_to_wall_clock = a.sim;
  auto device = kinect::KinectDevice::start(std::move(transport), options);
  if (!device.has_value()) fail("cannot start the camera: " + kinect::to_string(device.error()));
  kinect::KinectDevice& d = *device.value();
  if (auto ok = graphs::write_fakenect_device(dir / "device.json", d.calibration()); !ok)
    fail(ok.error().to_string());

  std::ofstream index(dir / "INDEX.txt", std::ios::app);
  std::vector<std::uint8_t> rgb(kinect::DEPTH_PIXELS * 3);
  std::uint64_t depth_records = 0, colour_records = 0, tilt_records = 0, tilt_written = 0;
  const auto start = std::chrono::steady_clock::now();
  const auto deadline =
      start + std::chrono::milliseconds(static_cast<std::int64_t>(a.frames) * 67 + 3000);
  while (depth_records < a.frames && std::chrono::steady_clock::now() < deadline) {
    const kinect::DepthFrame* f = d.latest_depth();
    if (f == nullptr) {
      std::this_thread::sleep_for(std::chrono::milliseconds(2));
      continue;
    }
    const double now = wall_seconds();
    // The accelerometer, as libfreenect's recorder writes it: an a- record of the raw state before
    // the frame, whenever the driver read a new one (about every 100 ms).
    if (const kinect::RawTiltReading t = d.raw_tilt(); t.sequence != tilt_written) {
      tilt_written = t.sequence;
      const formats::FakenectTilt tilt{t.accel_counts[0], t.accel_counts[1], t.accel_counts[2],
                                       t.tilt_raw, t.status_raw};
      const std::string name =
          formats::fakenect_name('a', now, static_cast<std::uint32_t>(f->device_ticks));
      if (auto ok = formats::write_fakenect_tilt(dir / name, tilt); !ok)
        fail(ok.error().to_string());
      index << name << '\n';
      ++tilt_records;
    }
    if (f->has_colour) {
      kernels::demosaic_grbg(f->bayer, kinect::DEPTH_WIDTH, kinect::DEPTH_HEIGHT, rgb);
      const std::string name =
          formats::fakenect_name('r', now, static_cast<std::uint32_t>(f->colour_ticks));
      if (auto ok = formats::write_fakenect_rgb(dir / name, rgb); !ok) fail(ok.error().to_string());
      index << name << '\n';
      ++colour_records;
    }
    const std::string name =
        formats::fakenect_name('d', now, static_cast<std::uint32_t>(f->device_ticks));
    if (auto ok = formats::write_fakenect_depth(dir / name, f->raw); !ok)
      fail(ok.error().to_string());
    index << name << '\n' << std::flush;
    if (!index) fail("cannot write " + (dir / "INDEX.txt").string());
    ++depth_records;
  }
  const kinect::CameraHealth h = d.health();
  std::cout << "recorded " << depth_records << " depth and " << colour_records
            << " colour frames and " << tilt_records << " accelerometer records to " << a.dir
            << " (camera: " << h.frames_degraded << " degraded, " << h.frames_dropped
            << " dropped, " << h.frames_overwritten << " not taken in time; lost packets "
            << h.depth.lost_packets << ")\n";
  if (depth_records < a.frames)
    fail("the camera delivered " + std::to_string(depth_records) + " of " +
         std::to_string(a.frames) + " frames in time");
}

}  // namespace

void add_kinect_record_command(CLI::App& kinect_command) {
  auto a = std::make_shared<RecordArgs>();
  auto* cmd = kinect_command.add_subcommand(
      "record",
      "record depth and colour in libfreenect's fakenect format (replay: run --source replay:DIR)");
  cmd->add_option("DIR", a->dir, "a new directory")->required();
  cmd->add_flag("--sim", a->sim, "record the simulated camera (no USB needed)");
  cmd->add_option("--sim-drop", a->sim_drop, "simulated packet loss rate")
      ->check(CLI::Range(0.0, 0.5));
  cmd->add_option("--serial", a->serial, "which camera (default: the first)");
  cmd->add_option("--frames", a->frames, "depth frames to record (default 90)")
      ->check(CLI::Range(1, 1'000'000));
  cmd->add_flag("--no-colour", a->no_colour, "depth only");
  cmd->callback([a] { record(*a); });
}

}  // namespace orthoflow::apps
