// libfreenect 0.5.3 (Debian's, an independent host implementation) against the simulated Kinect
// through the sim_libusb shim. freenect_client (a C program linked with libfreenect only) and
// /usr/bin/fakenect-record run as child processes with LD_LIBRARY_PATH=<the shim's directory>;
// this process keeps the real libusb. What they wrote is compared with SimKinectDevice built
// from the same ORTHOFLOW_SIM_KINECT string, and libfreenect's FREENECT_DEPTH_MM with orthoflow's
// own raw-to-millimetre table (drivers/kinect/kinect_depth.hpp), and FREENECT_DEPTH_REGISTERED with
// orthoflow's depth-to-colour registration (drivers/kinect/kinect_registration.hpp).
#include <fcntl.h>
#include <gtest/gtest.h>
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <climits>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <map>
#include <set>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "drivers/kinect/kinect_control.hpp"
#include "drivers/kinect/kinect_depth.hpp"
#include "drivers/kinect/kinect_registration.hpp"
#include "simulation/devices/sim_kinect_device.hpp"
#include "simulation/devices/sim_usb_transport.hpp"
#include "tests/support/sim_libusb/sim_kinect_env.hpp"

extern char** environ;

namespace orthoflow::sim_libusb {
namespace {

namespace fs = std::filesystem;
using namespace std::chrono_literals;
using simulation::SimKinectConfig;
using simulation::SimKinectDevice;

constexpr std::size_t PIXELS = 640 * 480;

struct Child {
  int status = -1;  // waitpid status
  double seconds = 0.0;
};

// Runs @p argv with the shim in LD_LIBRARY_PATH plus @p env, stdout and stderr to @p log. With
// @p interrupt_after > 0 it gets SIGINT after that long; it is killed after @p limit.
Child run(const std::vector<std::string>& argv, const std::map<std::string, std::string>& env,
          const fs::path& log, std::chrono::milliseconds interrupt_after = 0ms,
          std::chrono::milliseconds limit = 60s) {
  std::map<std::string, std::string> vars;
  for (char** e = environ; *e != nullptr; ++e) {
    const std::string kv = *e;
    const std::size_t eq = kv.find('=');
    if (eq != std::string::npos) vars[kv.substr(0, eq)] = kv.substr(eq + 1);
  }
  vars["LD_LIBRARY_PATH"] = SIM_LIBUSB_DIR;
  vars.erase(ENV_KINECT);
  vars.erase(ENV_PACE);
  for (const auto& [k, v] : env) vars[k] = v;
  std::vector<std::string> env_strings;
  for (const auto& [k, v] : vars) env_strings.push_back(k + "=" + v);
  std::vector<char*> envp;
  for (std::string& s : env_strings) envp.push_back(s.data());
  envp.push_back(nullptr);
  std::vector<std::string> args = argv;
  std::vector<char*> argp;
  for (std::string& s : args) argp.push_back(s.data());
  argp.push_back(nullptr);

  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_addopen(&actions, 1, log.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
  posix_spawn_file_actions_adddup2(&actions, 1, 2);
  pid_t pid = 0;
  const auto start = std::chrono::steady_clock::now();
  const int spawned = posix_spawn(&pid, argp[0], &actions, nullptr, argp.data(), envp.data());
  posix_spawn_file_actions_destroy(&actions);
  Child child;
  if (spawned != 0) return child;
  bool interrupted = false;
  for (;;) {
    int status = 0;
    const pid_t r = waitpid(pid, &status, WNOHANG);
    const auto elapsed = std::chrono::steady_clock::now() - start;
    if (r == pid) {
      child.status = status;
      child.seconds = std::chrono::duration<double>(elapsed).count();
      return child;
    }
    if (interrupt_after > 0ms && !interrupted && elapsed >= interrupt_after) {
      kill(pid, SIGINT);
      interrupted = true;
    }
    if (elapsed >= limit) kill(pid, SIGKILL);
    std::this_thread::sleep_for(10ms);
  }
}

std::string read_text(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

std::vector<std::uint16_t> read_u16(const fs::path& path, std::size_t skip = 0) {
  const std::string bytes = read_text(path);
  std::vector<std::uint16_t> out;
  if (bytes.size() < skip) return out;
  out.resize((bytes.size() - skip) / 2);
  std::memcpy(out.data(), bytes.data() + skip, out.size() * 2);
  return out;
}

fs::path fresh_dir(const std::string& name) {
  const fs::path dir = fs::path(SCRATCH_DIR) / name;
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir;
}

bool exited_ok(const Child& c) {
  return c.status >= 0 && WIFEXITED(c.status) && WEXITSTATUS(c.status) == 0;
}

// Runs freenect_client in @p mode for @p frames frames; returns its output directory.
fs::path run_client(const std::string& name, const std::string& mode, int frames,
                    const std::map<std::string, std::string>& env, Child* child = nullptr) {
  const fs::path dir = fresh_dir(name);
  const Child c =
      run({FREENECT_CLIENT, mode, std::to_string(frames), dir.string()}, env, dir / "log.txt");
  EXPECT_TRUE(exited_ok(c)) << "freenect_client " << mode << " failed:\n"
                            << read_text(dir / "log.txt");
  if (child != nullptr) *child = c;
  return dir;
}

// The simulator's Calibration as orthoflow's driver would read it (with libfreenect's 2.4 cm).
drivers::kinect::Calibration calibration_of(const SimKinectConfig& c) {
  drivers::kinect::Calibration cal;
  cal.zero_plane.dcmos_emitter_dist_cm = static_cast<float>(c.depth.emitter_dist_cm);
  cal.zero_plane.dcmos_rcmos_dist_cm = 2.4F;
  cal.zero_plane.reference_distance_mm = static_cast<float>(c.depth.ref_dist_mm);
  cal.zero_plane.reference_pixel_size_mm = static_cast<float>(c.depth.ref_pix_mm);
  cal.const_shift = static_cast<std::uint16_t>(c.depth.const_shift + 0.5);
  cal.reported_rcmos_dist_cm = static_cast<float>(c.calibration.dcmos_rcmos_dist_cm);
  return cal;
}

// The registration words and pad info the simulated camera answers (its built-in words are not
// in its config), read with orthoflow's own control exchange over the simulated transport.
drivers::kinect::Calibration with_device_registration(const SimKinectConfig& c,
                                                      drivers::kinect::Calibration cal) {
  using namespace drivers::kinect;
  simulation::SimUsbTransport usb;
  usb.add_kinect(c);
  auto list = usb.enumerate(VENDOR_MICROSOFT, PID_CAMERA);
  EXPECT_TRUE(list.has_value() && !list->empty());
  if (!list.has_value() || list->empty()) return cal;
  auto handle = usb.open(list->front());
  EXPECT_TRUE(handle.has_value());
  if (!handle.has_value()) return cal;
  KinectControl control(usb, *handle);
  auto read = control.read_calibration(Model::K1414);
  EXPECT_TRUE(read.has_value()) << (read ? "" : to_string(read.error()));
  if (!read.has_value()) return cal;
  cal.reg = read->reg;
  cal.pad = read->pad;
  return cal;
}

TEST(SimLibusbFreenect, TheLoaderPicksTheShimForLibfreenect) {
  const fs::path dir = fresh_dir("ldd");
  const Child c = run({"/usr/bin/ldd", FREENECT_CLIENT}, {}, dir / "ldd.txt");
  ASSERT_TRUE(exited_ok(c));
  const std::string out = read_text(dir / "ldd.txt");
  EXPECT_NE(out.find(std::string("libusb-1.0.so.0 => ") + SIM_LIBUSB_DIR + "/libusb-1.0.so.0"),
            std::string::npos)
      << out;
}

TEST(SimLibusbFreenect, Raw11BitFramesEqualTheSimulatorsImageAtWallClockPace) {
  constexpr int FRAMES = 10;
  Child child;
  const fs::path dir = run_client("raw11", "11bit", FRAMES, {}, &child);
  // Realtime pacing: 30 frames per second, so 10 frames take at least 9 frame periods.
  EXPECT_GE(child.seconds, 9.0 / 30.0 - 0.02);
  std::cout << "[ info ] " << FRAMES << " frames at realtime pace took " << child.seconds << " s\n";
  EXPECT_NE(read_text(dir / "devices.txt").find("count 1\nserial A00364A11700045A\n"),
            std::string::npos)
      << read_text(dir / "devices.txt");
  auto configs = parse_kinects("");
  ASSERT_TRUE(configs.has_value());
  SimKinectDevice reference(configs->at(0));
  std::vector<std::uint16_t> expected(PIXELS);
  std::vector<std::uint16_t> frame0(PIXELS);
  reference.depth_raw_image(0, frame0);
  for (int i = 0; i < FRAMES; ++i) {
    reference.depth_raw_image(static_cast<std::uint64_t>(i), expected);
    // The default scene is rendered once: every frame is the same image.
    EXPECT_EQ(expected, frame0);
    const auto got = read_u16(dir / ("11bit-" + std::to_string(i) + ".raw"));
    ASSERT_EQ(got.size(), PIXELS);
    EXPECT_TRUE(got == expected) << "frame " << i;
  }
}

TEST(SimLibusbFreenect, RampFramesLineUpFrameByFrame) {
  constexpr int FRAMES = 6;
  const fs::path dir =
      run_client("ramp", "11bit", FRAMES, {{ENV_KINECT, "depth=ramp"}, {ENV_PACE, "max"}});
  auto configs = parse_kinects("depth=ramp");
  ASSERT_TRUE(configs.has_value());
  SimKinectDevice reference(configs->at(0));
  std::vector<std::uint16_t> expected(PIXELS);
  std::istringstream index(read_text(dir / "11bit-index.txt"));
  std::vector<std::uint32_t> stamps;
  for (int i = 0; i < FRAMES; ++i) {
    int n = 0;
    std::uint32_t stamp = 0;
    ASSERT_TRUE(index >> n >> stamp);
    stamps.push_back(stamp);
    // libfreenect's first frame is the stream's frame 0; then one per 2,000,000 ticks.
    reference.depth_raw_image(static_cast<std::uint64_t>(i), expected);
    const auto got = read_u16(dir / ("11bit-" + std::to_string(i) + ".raw"));
    ASSERT_EQ(got.size(), PIXELS);
    EXPECT_TRUE(got == expected) << "frame " << i;
    if (i > 0) { EXPECT_EQ(stamps[i] - stamps[i - 1], 2'000'000U) << "frame " << i; }
  }
}

TEST(SimLibusbFreenect, A1473TakesItsSerialFromTheAudioSiblingOnTheSameHub) {
  // libfreenect matches the audio function to a 1473 camera by libusb_get_parent(); the 1414
  // motor by its index. Two Kinects on two hubs: each camera must get its own serial.
  const fs::path two = run_client(
      "two", "11bit", 1,
      {{ENV_KINECT, "model=1414;model=1473,serial=B00367707227042B"}, {ENV_PACE, "max"}});
  EXPECT_EQ(read_text(two / "devices.txt"),
            "count 2\nserial A00364A11700045A\nserial B00367707227042B\n");
  // Streaming from a 1473 alone: no motor; the LED and firmware steps on the audio function fail
  // (bulk transfers stall) and libfreenect carries on, as it does without audios.bin.
  const char* text = "model=1473,serial=B00367707227042B,depth=ramp";
  const fs::path dir = run_client("k1473", "11bit", 3, {{ENV_KINECT, text}, {ENV_PACE, "max"}});
  EXPECT_EQ(read_text(dir / "devices.txt"), "count 1\nserial B00367707227042B\n");
  auto configs = parse_kinects(text);
  ASSERT_TRUE(configs.has_value());
  SimKinectDevice reference(configs->at(0));
  std::vector<std::uint16_t> expected(PIXELS);
  for (int i = 0; i < 3; ++i) {
    reference.depth_raw_image(static_cast<std::uint64_t>(i), expected);
    const auto got = read_u16(dir / ("11bit-" + std::to_string(i) + ".raw"));
    EXPECT_TRUE(got == expected) << "frame " << i;
  }
}

TEST(SimLibusbFreenect, MillimetreFramesMatchOrthoflowsDepthTableWithinOneMillimetre) {
  constexpr int FRAMES = 3;
  const fs::path dir = run_client("mm", "mm", FRAMES, {{ENV_PACE, "max"}});
  auto configs = parse_kinects("");
  ASSERT_TRUE(configs.has_value());
  SimKinectDevice reference(configs->at(0));
  std::vector<std::uint16_t> raw(PIXELS);
  reference.depth_raw_image(0, raw);
  const drivers::kinect::DepthTableMm table =
      drivers::kinect::make_depth_table_mm(calibration_of(configs->at(0)));
  int max_diff = 0;
  std::size_t differing = 0;
  std::size_t valid = 0;
  std::map<int, std::size_t> histogram;
  for (int i = 0; i < FRAMES; ++i) {
    const auto got = read_u16(dir / ("mm-" + std::to_string(i) + ".raw"));
    ASSERT_EQ(got.size(), PIXELS);
    for (std::size_t p = 0; p < PIXELS; ++p) {
      const int d = std::abs(static_cast<int>(got[p]) - static_cast<int>(table[raw[p]]));
      max_diff = std::max(max_diff, d);
      differing += d != 0 ? 1 : 0;
      valid += table[raw[p]] != 0 ? 1 : 0;
      ++histogram[d];
    }
  }
  std::cout << "[ info ] DEPTH_MM vs make_depth_table_mm over " << FRAMES * PIXELS << " pixels ("
            << valid << " with depth): max |diff| " << max_diff << " mm, " << differing
            << " differ\n";
  EXPECT_LE(max_diff, 1);
  EXPECT_GT(valid, PIXELS / 2);
}

// The millimetre values libfreenect 0.5.3 makes of the raw values orthoflow calls "no reading"
// near the pole: it converts the (huge, negative) double to uint16_t without clamping, which on
// x86-64 truncates to int32 (INT32_MIN when out of range) and keeps the low 16 bits. Those that
// land in 1..9999 are registered by libfreenect as if they were depths (KINECT_V1.md 8.2 says to
// clamp first; orthoflow does).
std::set<std::uint16_t> libfreenect_pole_artefacts(const drivers::kinect::Calibration& cal) {
  std::set<std::uint16_t> out;
  const drivers::kinect::DepthTableMm table = drivers::kinect::make_depth_table_mm(cal);
  const auto& zp = cal.zero_plane;
  for (int raw = 0; raw < 2047; ++raw) {
    if (table[static_cast<std::size_t>(raw)] != 0) continue;
    const double x = (raw - 4.0 * cal.const_shift) / 4.0 - 0.375;
    const double m = x * static_cast<double>(zp.reference_pixel_size_mm);
    const double ref = zp.reference_distance_mm;
    const double v = 10.0 * (m * ref / (static_cast<double>(zp.dcmos_emitter_dist_cm) - m) + ref);
    const std::int64_t i =
        std::isfinite(v) && std::abs(v) < 2147483648.0 ? static_cast<std::int64_t>(v) : INT32_MIN;
    const auto u = static_cast<std::uint16_t>(static_cast<std::uint64_t>(i) & 0xFFFFU);
    if (u != 0 && u < 10000) out.insert(u);
  }
  return out;
}

// Runs freenect_client in registered mode on the Kinect @p text describes and compares each
// frame with Registration::register_depth of the simulator's raw frame; returns the pixels with
// depth in orthoflow's output, summed over the frames.
std::size_t compare_registered(const std::string& name, const std::string& text, int frames) {
  const fs::path dir =
      run_client(name, "registered", frames, {{ENV_KINECT, text}, {ENV_PACE, "max"}});
  auto configs = parse_kinects(text);
  EXPECT_TRUE(configs.has_value());
  if (!configs.has_value()) return 0;
  SimKinectDevice reference(configs->at(0));
  const drivers::kinect::Calibration cal =
      with_device_registration(configs->at(0), calibration_of(configs->at(0)));
  auto registration = drivers::kinect::Registration::create(cal);
  EXPECT_TRUE(registration.has_value()) << to_string(registration.error());
  if (!registration.has_value()) return 0;
  const std::set<std::uint16_t> artefacts = libfreenect_pole_artefacts(cal);
  std::vector<std::uint16_t> raw(PIXELS);
  std::vector<std::uint16_t> expected(PIXELS);
  std::size_t total_valid = 0;
  for (int i = 0; i < frames; ++i) {
    reference.depth_raw_image(static_cast<std::uint64_t>(i), raw);
    registration->register_depth(raw, expected);
    const auto got = read_u16(dir / ("registered-" + std::to_string(i) + ".raw"));
    EXPECT_EQ(got.size(), PIXELS);
    if (got.size() != PIXELS) return total_valid;
    int max_diff = 0;
    std::size_t differing = 0;
    std::size_t explained = 0;  // libfreenect wrote one of its pole artefacts there
    std::size_t got_valid = 0;
    std::size_t valid = 0;
    for (std::size_t p = 0; p < PIXELS; ++p) {
      const int d = std::abs(static_cast<int>(got[p]) - static_cast<int>(expected[p]));
      max_diff = std::max(max_diff, d);
      differing += d != 0 ? 1 : 0;
      explained += d != 0 && artefacts.count(got[p]) != 0 ? 1 : 0;
      got_valid += got[p] != 0 ? 1 : 0;
      valid += expected[p] != 0 ? 1 : 0;
    }
    total_valid += valid;
    std::cout << "[ info ] " << name << " DEPTH_REGISTERED frame " << i
              << " vs Registration::register_depth: " << PIXELS << " pixels compared, " << got_valid
              << " with depth in libfreenect's, " << valid << " in orthoflow's, " << differing
              << " differ (" << explained
              << " of them libfreenect's unclamped pole values), max |diff| " << max_diff
              << " mm\n";
    EXPECT_EQ(differing - explained, 0U) << name << " frame " << i;
  }
  return total_valid;
}

// Bit for bit, except where libfreenect registers its own unclamped conversion of raw values
// at the pole (the ramp has them; the tabletop does not). The simulator's built-in registration
// words are invented (sim_kinect_device.cpp): they map only about 6 % of the depth pixels into the
// colour image (18187 of 307200 on the default tabletop), so the check is real but sparse;
// realistic words need a simulator knob.
TEST(SimLibusbFreenect, RegisteredFramesEqualOrthoflowsRegistration) {
  EXPECT_GT(compare_registered("registered", "", 2), 2 * 10000U);
  EXPECT_FALSE(libfreenect_pole_artefacts(drivers::kinect::Calibration{}).empty());
  // The ramp covers every raw value, the pole and "no reading" included, and changes per frame.
  EXPECT_GT(compare_registered("registered_ramp", "depth=ramp", 3), 0U);
}

TEST(SimLibusbFreenect, FakenectRecordWritesTheSimulatorsRawFrames) {
  if (std::string(FAKENECT_RECORD).empty() || !fs::exists(FAKENECT_RECORD))
    GTEST_SKIP() << "fakenect-record not installed (libfreenect-bin)";
  const fs::path base = fresh_dir("fakenect");
  const fs::path out = base / "record";  // fakenect-record makes it; it must not exist
  const Child c = run({FAKENECT_RECORD, out.string()}, {}, base / "log.txt", 1500ms, 20s);
  const std::string log = read_text(base / "log.txt");
  ASSERT_TRUE(c.status >= 0 && WIFEXITED(c.status)) << "fakenect-record did not exit:\n" << log;
  EXPECT_NE(log.find("Caught signal, cleaning up"), std::string::npos) << log;
  ASSERT_TRUE(fs::exists(out / "INDEX.txt")) << log;

  auto configs = parse_kinects("");
  ASSERT_TRUE(configs.has_value());
  SimKinectDevice reference(configs->at(0));
  std::vector<std::uint16_t> expected(PIXELS);
  reference.depth_raw_image(0, expected);
  std::istringstream index(read_text(out / "INDEX.txt"));
  std::map<char, std::size_t> counts;
  std::string name;
  const std::string header = "P5 640 480 65535\n";
  while (std::getline(index, name)) {
    if (name.empty()) continue;
    ++counts[name[0]];
    ASSERT_TRUE(fs::exists(out / name)) << name;
    if (name[0] != 'd') continue;
    const std::string bytes = read_text(out / name);
    ASSERT_EQ(bytes.substr(0, header.size()), header) << name;
    ASSERT_EQ(bytes.size(), header.size() + PIXELS * 2) << name;
    const auto got = read_u16(out / name, header.size());
    EXPECT_TRUE(got == expected) << name;
  }
  std::cout << "[ info ] fakenect-record in " << c.seconds << " s: " << counts['d'] << " depth, "
            << counts['r'] << " rgb, " << counts['a'] << " accel files\n";
  EXPECT_GE(counts['d'], 10U);  // ~1.5 s at 30 Hz, minus start-up
  EXPECT_GE(counts['r'], 10U);
  EXPECT_GE(counts['a'], 1U);
  // libfreenect 0.5.3 writes no device.json (added in 0.6.0, commit 24a6810): report what exists.
  if (fs::exists(out / "device.json")) {
    std::cout << "[ info ] device.json: " << read_text(out / "device.json") << "\n";
  } else {
    std::cout << "[ info ] no device.json (fakenect-record of libfreenect 0.5.3 writes none)\n";
  }
}

}  // namespace
}  // namespace orthoflow::sim_libusb
