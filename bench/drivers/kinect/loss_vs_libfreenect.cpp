// What a host driver delivers from a lossy Kinect depth stream, frame by frame against the truth
// (issue 18; bench/drivers/kinect/loss_vs_libfreenect.sh runs both sides and prints the table).
//
//   loss_vs_libfreenect orthoflow PERIODS
//       streams depth through orthoflow's KinectCamera on LibusbTransport (default CameraOptions),
//       run with LD_LIBRARY_PATH=<the sim_libusb shim's directory>: this binary links the real
//       libusb-1.0 and the dynamic loader binds it to the shim.
//   loss_vs_libfreenect freenect PERIODS < records
//       reads the records `freenect_client 11bit PERIODS -` (tests/support/sim_libusb) writes: what
//       libfreenect 0.5.3 delivered to its depth callback from the same simulated stream.
//
// Both build the reference SimKinectDevice from ORTHOFLOW_SIM_KINECT exactly as the shim does
// (sim_kinect_env.hpp; one Kinect, depth=ramp) and compare every delivered frame with
// SimKinectDevice::depth_raw_image of its stream frame index k. k comes from the device timestamp
// (60 MHz; the simulator's frames are exactly 2,000,000 ticks apart) anchored on the content of the
// first delivered frame: the ramp, raw = 300 + (x + 2 y + 13 k) mod 1500, tells k (mod 1500) from
// any pixel, and the first frame's majority vote fixes the offset. Every later frame's own vote is
// checked against its timestamp (misnumbered). Frames with k >= PERIODS are not counted; the run
// ends at the first one. Output: one "key value" line per number, for the script.
#include <algorithm>
#include <array>
#include <chrono>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <string_view>
#include <vector>

#include "drivers/kinect/kinect_camera.hpp"
#include "drivers/usb/libusb_transport.hpp"
#include "simulation/devices/sim_kinect_device.hpp"
#include "tests/support/sim_libusb/sim_kinect_env.hpp"

namespace {

namespace dk = orthoflow::drivers::kinect;
using orthoflow::simulation::SimKinectConfig;
using orthoflow::simulation::SimKinectDevice;

constexpr std::uint16_t NO_READING = 2047;
constexpr std::uint32_t TICKS_PER_FRAME = 2'000'000;
constexpr std::uint32_t RAMP_PERIOD = 1500;  // 13 k mod 1500 repeats after 1500 frames
constexpr std::uint32_t INVERSE_13 = 577;    // 13 * 577 = 7501 = 1 (mod 1500)
constexpr std::uint64_t MAX_PERIODS = 1400;  // below RAMP_PERIOD: the content vote is unique

/// The stream frame index (mod 1500) the ramp pixels of @p raw vote for, and the share of the
/// non-hole pixels that voted for it (0 when every pixel is a hole).
struct Vote {
  std::uint32_t k = 0;
  double share = 0.0;
};
Vote ramp_vote(const std::vector<std::uint16_t>& raw) {
  std::array<std::uint32_t, RAMP_PERIOD> votes{};
  std::uint32_t voters = 0;
  for (std::size_t i = 0; i < raw.size(); ++i) {
    const std::uint32_t v = raw[i];
    if (v == NO_READING || v < 300 || v >= 300 + RAMP_PERIOD) continue;
    const auto x = static_cast<std::uint32_t>(i % dk::DEPTH_WIDTH);
    const auto y = static_cast<std::uint32_t>(i / dk::DEPTH_WIDTH);
    // v - 300 = (x + 2 y + 13 k) mod 1500  =>  13 k = (v - 300 - x - 2 y) mod 1500.
    const std::uint32_t r = (v - 300 + 3 * RAMP_PERIOD - (x + 2 * y) % RAMP_PERIOD) % RAMP_PERIOD;
    ++votes[(r * INVERSE_13) % RAMP_PERIOD];
    ++voters;
  }
  const auto best = std::max_element(votes.begin(), votes.end());
  return {static_cast<std::uint32_t>(best - votes.begin()),
          voters == 0 ? 0.0 : static_cast<double>(*best) / voters};
}

/// Compares delivered frames with the simulator's, one at a time (nothing stored but counters).
class Tally {
 public:
  Tally(const SimKinectConfig& config, std::uint64_t periods)
      : device_(config),
        periods_(periods),
        seen_(periods, 0),
        truth_(dk::DEPTH_PIXELS),
        previous_(dk::DEPTH_PIXELS),
        next_(dk::DEPTH_PIXELS) {}

  /// Adds one delivered frame (@p ticks: its device timestamp, low 32 bits). @p complete is the
  /// driver's own "no packet missing" flag (orthoflow), or -1 when the driver has none.
  /// @return false once a frame at or past PERIODS arrived (the run is over).
  bool add(std::uint32_t ticks, const std::vector<std::uint16_t>& raw, int complete) {
    const Vote vote = ramp_vote(raw);
    if (!anchored_) {
      if (vote.share < 0.5) {
        std::fprintf(stderr,
                     "loss_vs_libfreenect: the first frame is not a ramp frame (best vote %.2f): "
                     "ORTHOFLOW_SIM_KINECT needs depth=ramp\n",
                     vote.share);
        std::exit(1);
      }
      anchored_ = true;
      first_ticks_ = ticks;
      first_k_ = vote.k;
    }
    const std::uint32_t since = ticks - first_ticks_;  // mod 2^32, as the device clock wraps
    if (since % TICKS_PER_FRAME != 0) ++off_grid_;
    const std::uint64_t k = first_k_ + since / TICKS_PER_FRAME;
    if (k >= periods_) {
      ++past_end_;
      return false;
    }
    ++delivered_;
    if (vote.share > 0.0 && vote.k != k % RAMP_PERIOD) ++misnumbered_;
    if (seen_[k]++ != 0) ++duplicates_;

    device_.depth_raw_image(k, truth_);
    if (k > 0) device_.depth_raw_image(k - 1, previous_);
    device_.depth_raw_image(k + 1, next_);
    std::uint64_t holes = 0;
    std::uint64_t wrong = 0;
    for (std::size_t i = 0; i < raw.size(); ++i) {
      const std::uint16_t v = raw[i];
      if (v == truth_[i]) continue;
      if (v == NO_READING) {
        ++holes;
        continue;
      }
      ++wrong;
      if (k > 0 && v == previous_[i]) {
        ++stale_pixels_;
      } else if (v == next_[i]) {
        ++next_frame_pixels_;
      } else {
        ++garbage_pixels_;
      }
    }
    if (holes == 0 && wrong == 0) ++identical_;
    if (holes > 0 && wrong == 0) ++holes_only_;
    if (wrong > 0) ++wrong_frames_;
    wrong_pixels_ += wrong;
    hole_pixels_ += holes;
    max_wrong_ = std::max(max_wrong_, wrong);
    if (complete == 1 && (holes > 0 || wrong > 0)) ++complete_but_differs_;
    if (complete == 0 && holes == 0 && wrong == 0) ++incomplete_but_identical_;
    return true;
  }

  void print() const {
    const auto never = static_cast<std::uint64_t>(std::count(seen_.begin(), seen_.end(), 0));
    std::printf("periods %llu\n", ull(periods_));
    std::printf("first_frame %llu\n", ull(first_k_));
    std::printf("delivered %llu\n", ull(delivered_));
    std::printf("identical %llu\n", ull(identical_));
    std::printf("holes_only %llu\n", ull(holes_only_));
    std::printf("wrong_frames %llu\n", ull(wrong_frames_));
    std::printf("wrong_pixels %llu\n", ull(wrong_pixels_));
    std::printf("wrong_stale %llu\n", ull(stale_pixels_));
    std::printf("wrong_next %llu\n", ull(next_frame_pixels_));
    std::printf("wrong_garbage %llu\n", ull(garbage_pixels_));
    std::printf("max_wrong_per_frame %llu\n", ull(max_wrong_));
    std::printf("hole_pixels %llu\n", ull(hole_pixels_));
    std::printf("never_delivered %llu\n", ull(never));
    std::printf("duplicates %llu\n", ull(duplicates_));
    std::printf("misnumbered %llu\n", ull(misnumbered_));
    std::printf("off_grid %llu\n", ull(off_grid_));
    std::printf("complete_but_differs %llu\n", ull(complete_but_differs_));
    std::printf("incomplete_but_identical %llu\n", ull(incomplete_but_identical_));
  }

 private:
  static unsigned long long ull(std::uint64_t v) { return static_cast<unsigned long long>(v); }

  SimKinectDevice device_;
  std::uint64_t periods_;
  std::vector<std::uint32_t> seen_;
  std::vector<std::uint16_t> truth_, previous_, next_;
  bool anchored_ = false;
  std::uint32_t first_ticks_ = 0;
  std::uint64_t first_k_ = 0;
  std::uint64_t delivered_ = 0, identical_ = 0, holes_only_ = 0, wrong_frames_ = 0;
  std::uint64_t wrong_pixels_ = 0, stale_pixels_ = 0, next_frame_pixels_ = 0, garbage_pixels_ = 0;
  std::uint64_t max_wrong_ = 0, hole_pixels_ = 0, duplicates_ = 0, misnumbered_ = 0;
  std::uint64_t off_grid_ = 0, past_end_ = 0, complete_but_differs_ = 0;
  std::uint64_t incomplete_but_identical_ = 0;
};

int run_orthoflow(Tally& tally, std::uint64_t periods) {
  using namespace std::chrono_literals;
  auto transport = orthoflow::drivers::LibusbTransport::create();
  if (!transport) {
    std::fprintf(stderr, "loss_vs_libfreenect: LibusbTransport: %s\n",
                 std::string(orthoflow::drivers::to_string(transport.error())).c_str());
    return 1;
  }
  auto camera_result = dk::KinectCamera::open(**transport, dk::CameraOptions{});
  if (!camera_result) {
    std::fprintf(stderr, "loss_vs_libfreenect: KinectCamera::open: %s\n",
                 std::string(dk::to_string(camera_result.error())).c_str());
    return 1;
  }
  dk::KinectCamera& camera = **camera_result;
  if (auto started = camera.start_depth(); !started) {
    std::fprintf(stderr, "loss_vs_libfreenect: start_depth: %s\n",
                 std::string(dk::to_string(started.error())).c_str());
    return 1;
  }
  const auto deadline = std::chrono::steady_clock::now() + 20s +
                        std::chrono::milliseconds(100 * static_cast<std::int64_t>(periods));
  bool running = true;
  bool reached = false;
  while (running && std::chrono::steady_clock::now() < deadline) {
    (void)camera.pump(5ms);  // errors are counted in health()
    if (const dk::DepthFrame* f = camera.latest_depth()) {
      running = tally.add(static_cast<std::uint32_t>(f->device_ticks), f->raw, f->complete ? 1 : 0);
      reached = !running;
    }
  }
  const dk::CameraHealth h = camera.health();
  (void)camera.stop_depth();
  tally.print();
  const auto u = [](std::uint64_t v) { return static_cast<unsigned long long>(v); };
  std::printf("health_frames_delivered %llu\n", u(h.frames_delivered));
  std::printf("health_frames_degraded %llu\n", u(h.frames_degraded));
  std::printf("health_frames_dropped %llu\n", u(h.frames_dropped));
  std::printf("health_frames_overwritten %llu\n", u(h.frames_overwritten));
  std::printf("health_lost_packets %llu\n", u(h.depth.lost_packets));
  std::printf("health_resyncs %llu\n", u(h.depth.resyncs));
  std::printf("health_frames_abandoned %llu\n", u(h.depth.frames_abandoned));
  std::printf("health_watchdog_restarts %llu\n", u(h.watchdog_restarts));
  std::printf("health_iso_errors %llu\n", u(h.iso_errors));
  if (!reached) std::fprintf(stderr, "loss_vs_libfreenect: the stream did not reach its end\n");
  return reached ? 0 : 1;
}

int run_freenect(Tally& tally) {
  std::vector<std::uint16_t> raw(dk::DEPTH_PIXELS);
  std::uint64_t records = 0;
  bool reached = false;
  for (;;) {
    std::uint32_t ticks = 0;
    if (std::fread(&ticks, sizeof ticks, 1, stdin) != 1) break;
    if (std::fread(raw.data(), sizeof(std::uint16_t), raw.size(), stdin) != raw.size()) {
      std::fprintf(stderr, "loss_vs_libfreenect: truncated record %llu\n",
                   static_cast<unsigned long long>(records));
      return 1;
    }
    ++records;
    if (!tally.add(ticks, raw, -1)) {
      reached = true;
      break;
    }
  }
  tally.print();
  std::printf("callbacks %llu\n", static_cast<unsigned long long>(records));
  if (!reached) std::fprintf(stderr, "loss_vs_libfreenect: the stream did not reach its end\n");
  return reached ? 0 : 1;
}

}  // namespace

int main(int argc, char** argv) {
  const std::string_view side = argc == 3 ? argv[1] : "";
  if (side != "orthoflow" && side != "freenect") {
    std::fprintf(stderr, "usage: loss_vs_libfreenect orthoflow|freenect PERIODS\n");
    return 2;
  }
  const std::uint64_t periods = std::strtoull(argv[2], nullptr, 10);
  if (periods < 2 || periods > MAX_PERIODS) {
    std::fprintf(stderr, "loss_vs_libfreenect: PERIODS must be in [2, %llu]\n",
                 static_cast<unsigned long long>(MAX_PERIODS));
    return 2;
  }
  auto configs = orthoflow::sim_libusb::kinects_from_env();
  if (!configs || configs->size() != 1 || !configs->front().depth_source) {
    std::fprintf(stderr, "loss_vs_libfreenect: %s must describe one Kinect with depth=ramp%s%s\n",
                 orthoflow::sim_libusb::ENV_KINECT, configs ? "" : ": ",
                 configs ? "" : configs.error().c_str());
    return 2;
  }
  Tally tally(configs->front(), periods);
  return side == "orthoflow" ? run_orthoflow(tally, periods) : run_freenect(tally);
}
