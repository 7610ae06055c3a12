// Does the web view slow the robot? The embedded tabletop graph on the 45 real Kinect frames of
// mOSD's learning split (../shared/data/mosd_learn, looped, read ahead), paced at 30 Hz as the
// Kinect paces it (one engine thread, the instructor off), run alone and with the web view's server
// (ui/) serving a viewer: Debian's headless Chromium with the page open at ?hz=30 (the state over
// the WebSocket at 30 Hz and the camera image, GET /api/camera.png drawn on the backend's thread,
// at up to 5 Hz), or a program polling the API as the page does (the server's share alone: what the
// robot pays when the operator's browser runs on another machine).
//
// A 2-vCPU machine's p99 drifts between runs by more than the bar (5 %), so the runs alternate in
// ROUNDS rounds (A B, then B A, ...: drift cancels), and every frame's exact latency (source stamp
// -> frame fully processed, RunOptions::latency_trace; the engine's histogram has 12.5 % buckets,
// too coarse for a 5 % bar) after each run's first WARMUP_FRAMES is pooled per side. Reported: the
// pooled p50 / p99 / max of each side, their p99 ratio (the bar: within 5 %), the median of
// the rounds' own p99 ratios, and deadline misses. Skipped without /usr/bin/chromium.
//
// usage: ui_latency_bench [--benchmark_...] (ORTHOFLOW_UI_BENCH_FRAMES: frames per run, default
// 450; ORTHOFLOW_UI_BENCH_ROUNDS: rounds, default 3)
#include <benchmark/benchmark.h>
#include <fcntl.h>
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cairo.h>

#include <algorithm>
#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <limits>
#include <random>
#include <string>
#include <thread>
#include <vector>

#include "engine/engine.hpp"
#include "engine/graph.hpp"
#include "engine/histogram.hpp"
#include "graphs/embedded_graphs.hpp"
#include "graphs/nodes/objects_output.hpp"
#include "graphs/tabletop.hpp"
#include "tests/support/pinhole_image.hpp"
#include "ui/background_thread.hpp"
#include "ui/camera_view.hpp"
#include "ui/graph_backend.hpp"
#include "ui/png_encode.hpp"
#include "ui/ui_client.hpp"
#include "ui/ui_server.hpp"

extern char** environ;

namespace {

namespace oe = orthoflow::engine;
namespace og = orthoflow::graphs;
namespace ou = orthoflow::ui;

constexpr const char* CHROMIUM = "/usr/bin/chromium";
constexpr const char* NICE = "/usr/bin/nice";

std::uint64_t env_count(const char* name, std::uint64_t fallback) {
  const char* n = std::getenv(name);
  const std::uint64_t v = n != nullptr ? std::strtoull(n, nullptr, 10) : 0;
  return v > 0 ? v : fallback;
}
std::uint64_t frames_per_run() { return env_count("ORTHOFLOW_UI_BENCH_FRAMES", 450); }
std::uint64_t rounds() { return env_count("ORTHOFLOW_UI_BENCH_ROUNDS", 3); }
constexpr std::uint64_t WARMUP_FRAMES = 30;  // each run's first second: start-up, not steady state

struct Latency {
  double p50_us = 0, p99_us = 0, max_us = 0, frames = 0, misses = 0;
};

// Exact nearest-rank percentiles of @p ns (sorted here), in microseconds.
Latency latency_of(std::vector<std::int64_t> ns, double misses) {
  Latency l;
  if (ns.empty()) return l;
  std::sort(ns.begin(), ns.end());
  l.p50_us = static_cast<double>(oe::exact_percentile(ns, 0.5)) / 1e3;
  l.p99_us = static_cast<double>(oe::exact_percentile(ns, 0.99)) / 1e3;
  l.max_us = static_cast<double>(ns.back()) / 1e3;
  l.frames = static_cast<double>(ns.size());
  l.misses = misses;
  return l;
}

// Headless Chromium on @p url for as long as this lives; with @p niced, at nice 19 (through
// /usr/bin/nice), as an operator would start a browser on the robot itself.
class Browser {
 public:
  Browser(const std::string& url, bool niced) {
    profile_ = (std::filesystem::temp_directory_path() /
                ("orthoflow_ui_bench_" + std::to_string(::getpid())))
                   .string();
    const std::string profile_arg = "--user-data-dir=" + profile_;
    std::vector<std::string> args = {CHROMIUM,
                                     "--headless=new",
                                     "--no-sandbox",
                                     "--disable-gpu",
                                     "--disable-dev-shm-usage",
                                     "--no-first-run",
                                     "--disable-background-networking",
                                     "--disable-component-update",
                                     "--disable-sync",
                                     profile_arg,
                                     "--window-size=1280,1100",
                                     url};
    if (niced) args.insert(args.begin(), {NICE, "-n", "19"});
    std::vector<char*> argv;
    for (std::string& a : args) argv.push_back(a.data());
    argv.push_back(nullptr);
    posix_spawn_file_actions_t files;
    posix_spawn_file_actions_init(&files);
    posix_spawn_file_actions_addopen(&files, 1, "/dev/null", O_WRONLY, 0);
    posix_spawn_file_actions_addopen(&files, 2, "/dev/null", O_WRONLY, 0);
    posix_spawnattr_t attr;
    posix_spawnattr_init(&attr);
    posix_spawnattr_setflags(&attr, POSIX_SPAWN_SETPGROUP);  // its own group: killed as one
    posix_spawnattr_setpgroup(&attr, 0);
    if (posix_spawn(&pid_, args[0].c_str(), &files, &attr, argv.data(), environ) != 0) pid_ = -1;
    posix_spawn_file_actions_destroy(&files);
    posix_spawnattr_destroy(&attr);
  }
  ~Browser() {
    if (pid_ > 0) {
      ::kill(-pid_, SIGTERM);
      int status = 0;
      ::waitpid(pid_, &status, 0);
    }
    std::error_code ignored;
    std::filesystem::remove_all(profile_, ignored);
  }
  Browser(const Browser&) = delete;
  Browser& operator=(const Browser&) = delete;
  [[nodiscard]] bool running() const noexcept { return pid_ > 0; }

 private:
  pid_t pid_ = -1;
  std::string profile_;
};

// A program polling the API as the page does: GET /api/state at 30 Hz and GET /api/camera.png at
// 5 Hz (the server's work without a browser's rendering beside the graph); with @p niced, from a
// thread at nice 19 (a client that yields the CPU to the graph, as one on another machine takes
// none of the robot's).
class Poller {
 public:
  Poller(std::uint16_t port, bool camera, bool niced) {
    thread_ = std::thread([this, port, camera, niced] {
      if (niced) ou::make_this_thread_background();
      const ou::ClientTarget target{"127.0.0.1", port, "", 2000};
      for (int tick = 0; !stop_.load(); ++tick) {
        (void)ou::send_ui_request(target, "GET", "/api/state", "");
        if (camera && tick % 6 == 0)
          (void)ou::send_ui_request(target, "GET", "/api/camera.png", "");
        std::this_thread::sleep_for(std::chrono::microseconds(33'333));
      }
    });
  }
  ~Poller() {
    stop_.store(true);
    thread_.join();
  }
  Poller(const Poller&) = delete;
  Poller& operator=(const Poller&) = delete;

 private:
  std::atomic<bool> stop_{false};
  std::thread thread_;
};

enum class Viewer { NONE, BROWSER, PROGRAM, PROGRAM_STATE_ONLY, BROWSER_NICED, PROGRAM_NICED };

// One run of the graph at 30 Hz; with a viewer, the web view and that viewer on it. Appends the
// exact latency of every frame after the first WARMUP_FRAMES to @p samples; @p camera_images gets
// the images the frame path copied for the viewer. @return the run's own percentiles (frames 0:
// it did not start).
Latency run_once(Viewer viewer, std::uint64_t frames, std::uint64_t& camera_images,
                 std::vector<std::int64_t>& samples) {
  const bool with_viewer = viewer != Viewer::NONE;
  auto spec = oe::parse_graph(std::string(og::embedded_tabletop_yaml()), "embedded:tabletop.yaml");
  if (!spec) return {};
  for (auto& node : spec->nodes) {
    if (node.kind == "recognise") node.params.assign("instructor", "0");
    if (node.kind == "synthetic_source") {  // real Kinect frames, read ahead, looped
      node.kind = "pcd_source";
      node.params = {};
      node.params.assign("dir", std::string(ORTHOFLOW_SHARED_DIR) + "/data/mosd_learn");
      node.params.assign("loop", "1");
    }
  }
  spec->period_ns = 1'000'000'000 / 30;
  auto learning = og::LearningService::open({});
  og::SessionLog log(nullptr);
  og::ObjectsHub hub;
  const auto registry = og::make_tabletop_registry(**learning, log, &hub);
  auto graph = oe::build_graph(*spec, registry);
  if (!graph) return {};
  oe::Engine engine(**graph, {1});
  std::unique_ptr<ou::GraphBackend> backend;
  std::unique_ptr<ou::UiServer> server;
  std::unique_ptr<Browser> browser;
  std::unique_ptr<Poller> poller;
  if (with_viewer) {
    auto opened = ou::GraphBackend::open(**learning, hub);
    if (!opened) return {};
    backend = std::move(*opened);
    backend->set_telemetry(&engine.stats());
    ou::UiServerConfig config;  // loopback, port 0
    config.max_stream_hz = 30.0;
    auto started = ou::UiServer::start(config, *backend);
    if (!started) return {};
    server = std::move(*started);
    if (viewer == Viewer::BROWSER || viewer == Viewer::BROWSER_NICED) {
      browser =
          std::make_unique<Browser>(server->url() + "?hz=30", viewer == Viewer::BROWSER_NICED);
      if (!browser->running()) return {};
    } else {
      poller = std::make_unique<Poller>(server->port(), viewer != Viewer::PROGRAM_STATE_ONLY,
                                        viewer == Viewer::PROGRAM_NICED);
    }
    // The browser's start (a second or more) is not the robot's steady state: wait until the
    // page runs (it asked for a camera image), then a little more.
    const auto now = [] { return std::chrono::steady_clock::now().time_since_epoch().count(); };
    const std::int64_t until = now() + 30'000'000'000;
    while (viewer != Viewer::PROGRAM_STATE_ONLY && !hub.camera().wanted(now()) && now() < until)
      std::this_thread::sleep_for(std::chrono::milliseconds(50));
    if (viewer != Viewer::PROGRAM_STATE_ONLY && !hub.camera().wanted(now())) return {};
    std::this_thread::sleep_for(std::chrono::seconds(1));
  }
  std::vector<std::int64_t> trace(frames);
  oe::RunOptions limits;
  limits.max_frames = frames;
  limits.latency_trace = trace;
  engine.run(limits);
  const auto& stats = engine.stats();
  trace.resize(std::min<std::size_t>(trace.size(), stats.frames_done.load()));
  if (trace.size() > WARMUP_FRAMES) trace.erase(trace.begin(), trace.begin() + WARMUP_FRAMES);
  samples.insert(samples.end(), trace.begin(), trace.end());
  const Latency l = latency_of(trace, static_cast<double>(stats.deadline_misses.load()));
  camera_images = hub.camera().copied();
  browser.reset();
  poller.reset();
  server.reset();
  backend.reset();
  return l;
}

// range(0): 0 = Debian's headless Chromium on the page, 1 = a program polling the state and the
// camera image as the page does, 2 = a program polling the state only, 3 = Chromium at nice 19,
// 4 = viewer 1 from a thread at nice 19.
void BM_FrameLatencyWithAViewer(benchmark::State& state) {
  constexpr Viewer VIEWERS[] = {Viewer::BROWSER, Viewer::PROGRAM, Viewer::PROGRAM_STATE_ONLY,
                                Viewer::BROWSER_NICED, Viewer::PROGRAM_NICED};
  const Viewer viewer = VIEWERS[static_cast<std::size_t>(state.range(0))];
  const bool browser = viewer == Viewer::BROWSER || viewer == Viewer::BROWSER_NICED;
  if (browser && ::access(CHROMIUM, X_OK) != 0) {
    state.SkipWithError("no /usr/bin/chromium (apt-get install chromium)");
    return;
  }
  const std::uint64_t frames = frames_per_run();
  std::vector<std::int64_t> alone_ns, watched_ns;
  std::vector<double> round_ratios;
  double alone_misses = 0, watched_misses = 0;
  std::uint64_t images = 0, none = 0;
  for (auto _ : state) {
    for (std::uint64_t r = 0; r < rounds(); ++r) {
      std::uint64_t round_images = 0;
      Latency a, w;
      if (r % 2 == 0) {
        a = run_once(Viewer::NONE, frames, none, alone_ns);
        w = run_once(viewer, frames, round_images, watched_ns);
      } else {
        w = run_once(viewer, frames, round_images, watched_ns);
        a = run_once(Viewer::NONE, frames, none, alone_ns);
      }
      if (a.frames == 0 || w.frames == 0) {
        state.SkipWithError("a run did not start (graph, server or browser)");
        return;
      }
      round_ratios.push_back(w.p99_us / a.p99_us);
      alone_misses += a.misses;
      watched_misses += w.misses;
      images += round_images;
    }
  }
  const Latency alone = latency_of(alone_ns, alone_misses);
  const Latency watched = latency_of(watched_ns, watched_misses);
  std::sort(round_ratios.begin(), round_ratios.end());
  state.counters["alone_p50_us"] = alone.p50_us;
  state.counters["alone_p99_us"] = alone.p99_us;
  state.counters["alone_max_us"] = alone.max_us;
  state.counters["ui_p50_us"] = watched.p50_us;
  state.counters["ui_p99_us"] = watched.p99_us;
  state.counters["ui_max_us"] = watched.max_us;
  state.counters["p99_ratio"] = watched.p99_us / alone.p99_us;
  state.counters["p99_ratio_round_median"] = round_ratios[round_ratios.size() / 2];
  state.counters["p99_ratio_round_min"] = round_ratios.front();
  state.counters["p99_ratio_round_max"] = round_ratios.back();
  state.counters["alone_deadline_misses"] = alone.misses;
  state.counters["ui_deadline_misses"] = watched.misses;
  state.counters["camera_images"] = static_cast<double>(images);
  state.counters["frames"] = watched.frames;
}
BENCHMARK(BM_FrameLatencyWithAViewer)
    ->ArgName("viewer")
    ->Arg(0)
    ->Arg(1)
    ->Arg(2)
    ->Arg(3)
    ->Arg(4)
    ->Iterations(1)
    ->Unit(benchmark::kSecond);

// The frame path's share: one copy of a 640 x 480 colour frame into the tap (320 x 240).
void BM_CameraTapCopy(benchmark::State& state) {
  const std::size_t n = 640 * 480;
  std::vector<float> x(n), y(n), z(n);
  std::vector<std::uint32_t> rgb(n, 0xFF806040U);
  for (std::size_t i = 0; i < n; ++i) {
    z[i] = 1.0F + static_cast<float>(i % 640) * 1e-3F;
    x[i] = (static_cast<float>(i % 640) - 320.0F) / 525.0F * z[i];
    y[i] = (static_cast<float>(i / 640) - 240.0F) / 525.0F * z[i];
  }
  oe::FrameHeader header;
  header.width = 640;
  header.height = 480;
  oe::FrameView frame;
  frame.header = &header;
  frame.cloud.points = {x, y, z};
  frame.cloud.width = 640;
  frame.cloud.height = 480;
  frame.rgb = rgb;
  og::CameraTap tap;
  tap.request(0, 0, std::numeric_limits<std::int64_t>::max() / 2);
  std::int64_t t = 1;
  for (auto _ : state) {
    header.frame_id = static_cast<std::uint64_t>(t);
    benchmark::DoNotOptimize(tap.offer(frame, t++));
  }
  og::CameraImage image;
  (void)tap.take(image, 0);
  state.counters["pixels"] = static_cast<double>(image.width * image.height);
}
BENCHMARK(BM_CameraTapCopy)->Unit(benchmark::kMicrosecond);

// The backend thread's share per image: the pinhole fit and the PNG (colour, 3 boxes).
void BM_CameraImageDraw(benchmark::State& state) {
  og::CameraImage image = orthoflow::test::pinhole_image(
      320, 240, 262.5, 160.0, 120.0,
      [](std::uint32_t, std::uint32_t v) { return 1.0F + 0.3F * static_cast<float>(v) / 240.0F; });
  image.rgb.resize(image.z.size());
  for (std::size_t i = 0; i < image.rgb.size(); ++i)
    image.rgb[i] = 0xFF000000U | (static_cast<std::uint32_t>(i % 320) << 16) |
                   static_cast<std::uint32_t>(i / 320);
  std::vector<ou::ObjectView> objects(3);
  for (std::size_t k = 0; k < objects.size(); ++k) {
    objects[k].track_id = k + 1;
    const float x0 = -0.3F + 0.2F * static_cast<float>(k);
    objects[k].bbox_min[0] = x0, objects[k].bbox_min[1] = -0.1F, objects[k].bbox_min[2] = 1.0F;
    objects[k].bbox_max[0] = x0 + 0.1F, objects[k].bbox_max[1] = 0.05F,
    objects[k].bbox_max[2] = 1.1F;
  }
  std::size_t bytes = 0;
  for (auto _ : state) {
    const ou::PinholeFit fit = ou::fit_pinhole(image);
    benchmark::DoNotOptimize(fit);
    bytes = ou::render_camera_png(image, objects).size();
  }
  state.counters["png_bytes"] = static_cast<double>(bytes);
}
BENCHMARK(BM_CameraImageDraw)->Unit(benchmark::kMicrosecond);

cairo_status_t append_to(void* closure, const unsigned char* data, unsigned int length) {
  static_cast<std::string*>(closure)->append(reinterpret_cast<const char*>(data), length);
  return CAIRO_STATUS_SUCCESS;
}

// The PNG of a camera-like 320 x 240 image (a smooth scene plus +-8 levels of sensor noise per
// channel, seeded: what a Kinect's colour looks like to zlib, unlike BM_CameraImageDraw's clean
// gradient): range(0) 0 = cairo's own writer (zlib's default level; the web view before), 1 =
// ui/png_encode (libpng, level 1, SUB filter; the web view now). Compare their times in one run.
void BM_PngEncode(benchmark::State& state) {
  constexpr int W = 320, H = 240;
  cairo_surface_t* surface = cairo_image_surface_create(CAIRO_FORMAT_RGB24, W, H);
  cairo_surface_flush(surface);
  unsigned char* pixels = cairo_image_surface_get_data(surface);
  const int stride = cairo_image_surface_get_stride(surface);
  std::mt19937 random(42);
  std::uniform_int_distribution<int> noise(-8, 8);
  auto level = [&](int base) {
    return static_cast<std::uint32_t>(std::clamp(base + noise(random), 0, 255));
  };
  for (int j = 0; j < H; ++j) {
    auto* row = reinterpret_cast<std::uint32_t*>(pixels + j * stride);
    for (int i = 0; i < W; ++i)
      row[i] = (level(60 + i / 2) << 16) | (level(90 + j / 3) << 8) | level(120 + (i + j) / 5);
  }
  cairo_surface_mark_dirty(surface);
  std::size_t bytes = 0;
  for (auto _ : state) {
    std::string png;
    if (state.range(0) == 0)
      cairo_surface_write_to_png_stream(surface, append_to, &png);
    else
      png = ou::encode_rgb24_png(pixels, stride, W, H);
    bytes = png.size();
    benchmark::DoNotOptimize(png.data());
  }
  cairo_surface_destroy(surface);
  state.counters["png_bytes"] = static_cast<double>(bytes);
}
BENCHMARK(BM_PngEncode)->ArgName("libpng_level1")->Arg(0)->Arg(1)->Unit(benchmark::kMicrosecond);

}  // namespace

BENCHMARK_MAIN();
