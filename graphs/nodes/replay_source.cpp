#include "graphs/nodes/replay_source.hpp"

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <optional>
#include <thread>

#include "drivers/kinect/kinect_camera.hpp"
#include "drivers/kinect/kinect_depth.hpp"
#include "drivers/kinect/kinect_gravity.hpp"
#include "formats/fakenect.hpp"
#include "formats/file_bytes.hpp"
#include "graphs/nodes/fakenect_calibration.hpp"
#include "graphs/nodes/node_support.hpp"
#include "graphs/nodes/recording_source.hpp"
#include "kernels/depth_projection.hpp"

namespace orthoflow::graphs {

namespace {

using engine::Message;
using engine::ParamMap;
namespace kinect = drivers::kinect;

/// "Up" for one depth record: from the last usable accelerometer record before it in INDEX.txt.
struct RecordedUp {
  std::array<float, 3> up{};  // all zero: none
  std::uint32_t age_ms = 0;
};

/// What a recording lacks, counted once at start-up.
struct RecordingStats {
  std::uint64_t frames_missing = 0, without_gravity = 0, accel_skipped = 0, out_of_order = 0;
};

/// Frames missing between consecutive depth records: device-time gaps of more than one and a
/// half 30 Hz periods (2,000,000 ticks of the 60 MHz clock each), rounded to whole frames.
std::uint64_t frames_missing(const std::vector<formats::FakenectEntry>& depth) {
  std::uint64_t missing = 0;
  for (std::size_t k = 1; k < depth.size(); ++k) {
    const std::uint32_t gap = depth[k].device_ticks - depth[k - 1].device_ticks;  // wraps
    if (gap > 3'000'000U) missing += (gap + 1'000'000U) / 2'000'000U - 1U;
  }
  return missing;
}

/// The depth records' "up" from the recording's accelerometer records (read once, at start-up).
/// A record that does not read, or whose reading is not a plausible gravity (all zero, a Kinect
/// being moved), is skipped and counted in @p unusable; frames before the first usable one have
/// none.
Result<std::vector<RecordedUp>, std::string> recorded_ups(
    const std::filesystem::path& dir, const std::vector<formats::FakenectEntry>& index,
    std::size_t& accel_records, std::size_t& unusable) {
  std::vector<RecordedUp> out;
  std::optional<std::array<float, 3>> last;
  double last_seconds = 0.0;
  for (const auto& e : index) {
    if (e.kind == 'a') {
      ++accel_records;
      auto tilt = formats::read_fakenect_tilt(dir / e.file);
      auto up =
          tilt ? kinect::up_from_accel(tilt->accel_x, tilt->accel_y, tilt->accel_z) : std::nullopt;
      if (!up) {
        ++unusable;
        continue;
      }
      last = up;
      last_seconds = e.host_seconds;
    } else if (e.kind == 'd') {
      RecordedUp r;
      if (last) {
        r.up = *last;
        const double age = std::max(0.0, (e.host_seconds - last_seconds) * 1000.0);
        r.age_ms = static_cast<std::uint32_t>(std::min(age, 4.0e9));
      }
      out.push_back(r);
    }
  }
  return out;
}

/// The depth records of a fakenect recording (ours or libfreenect's fakenect-record), read and
/// converted ahead on the decoder thread with the same code as the live camera (the device's
/// raw-to-metres table and pinhole, kinect_source), then emitted at the recorded pace (the host
/// times in the file names) or as fast as the graph takes them.
class ReplaySource final : public RecordingSource {
 public:
  ReplaySource(std::size_t capacity, const engine::NodeContext& context,
               std::vector<formats::FakenectEntry> entries, std::vector<RecordedUp> ups,
               const RecordingStats& stats, std::filesystem::path dir,
               const kinect::Calibration& calibration, bool paced, bool loop)
      : RecordingSource(capacity, context, paced, "replay_source: no record decoded within 5 s"),
        entries_(std::move(entries)),
        ups_(std::move(ups)),
        stats_(stats),
        dir_(std::move(dir)),
        raw_(kinect::DEPTH_PIXELS) {
    kinect::make_depth_table_m(calibration, table_m_);
    camera_ = kinect::depth_camera(calibration);
    std::vector<std::filesystem::path> files;
    for (const auto& e : entries_) files.push_back(dir_ / e.file);
    start_decoding(std::move(files), loop,
                   [this](std::size_t i, DecodeAhead::Slot& s) { decode(i, s); });
  }
  ~ReplaySource() override { stop_decoding(); }  // the decoder thread uses the members below

  /// The recording's account: depth records, frames missing between them (gaps in the device's
  /// 60 MHz timestamps of more than one 30 Hz frame period), depth records with no accelerometer
  /// reading before them, accelerometer records skipped (unreadable or implausible), and depth
  /// records skipped because INDEX.txt lists them after a later one (out of time order).
  const char* counter_group() const noexcept override { return "recording"; }
  std::size_t device_counters(std::span<engine::DeviceCounter> out) const noexcept override {
    const std::array<engine::DeviceCounter, 5> all{{{"depth_records", entries_.size()},
                                                    {"frames_missing", stats_.frames_missing},
                                                    {"without_gravity", stats_.without_gravity},
                                                    {"accel_skipped", stats_.accel_skipped},
                                                    {"out_of_order", stats_.out_of_order}}};
    const std::size_t k = std::min(out.size(), all.size());
    std::copy_n(all.begin(), k, out.begin());
    return k;
  }

 private:
  /// Decoder thread: one record into @p slot.
  void decode(std::size_t index, DecodeAhead::Slot& slot) {
    const formats::FakenectEntry& e = entries_[index];
    // Errors name the record as INDEX.txt lists it (a frame error's detail is short).
    auto bytes = formats::read_file_bytes(dir_ / e.file, std::size_t{1} << 20);
    auto read =
        bytes ? formats::parse_fakenect_depth(*bytes, e.file, raw_)
              : Result<void, formats::IoError>(err(formats::IoError{
                    bytes.error().code,
                    e.file + ": " + formats::read_failure_reason(bytes.error(), dir_ / e.file)}));
    if (!read) {
      slot.ok = false;
      slot.error = read.error();
      return;
    }
    slot.cloud.resize(kinect::DEPTH_WIDTH, kinect::DEPTH_HEIGHT);
    (void)kernels::depth_to_points(raw_, kinect::DEPTH_WIDTH, kinect::DEPTH_HEIGHT, table_m_,
                                   camera_, slot.cloud.points());
    if (index == 0) {
      first_seconds_ = e.host_seconds;
      ticks_ = e.device_ticks;
      last_ticks_ = e.device_ticks;
    }
    ticks_ += static_cast<std::uint32_t>(e.device_ticks - last_ticks_);  // unwrap the 32-bit clock
    last_ticks_ = e.device_ticks;
    slot.cloud.info.sensor_stamp_ns = static_cast<std::int64_t>(ticks_ * 50 / 3);
    slot.cloud.info.up = ups_[index].up;  // all zero when no usable accelerometer record came yet
    slot.cloud.info.up_age_ms = ups_[index].age_ms;
    slot.schedule_ns = static_cast<std::int64_t>((e.host_seconds - first_seconds_) * 1e9);
    slot.ok = true;
  }

  std::vector<formats::FakenectEntry> entries_;
  std::vector<RecordedUp> ups_;  // one per entry
  RecordingStats stats_;
  std::filesystem::path dir_;
  std::array<float, kernels::DISPARITY_TABLE_SIZE> table_m_{};
  kernels::DepthCamera camera_{};
  std::vector<std::uint16_t> raw_;  // decoder thread only
  double first_seconds_ = 0.0;
  std::uint64_t ticks_ = 0;
  std::uint32_t last_ticks_ = 0;
};

NodeResult make_replay(const ParamMap& params, const engine::NodeContext& context) {
  auto capacity = frame_capacity(context);
  if (!capacity) return err(capacity.error());
  if (auto ok = params.only({"dir", "pace", "loop"}); !ok) return err(ok.error());
  std::string dir, pace, e;
  std::int64_t loop = 0;
  take(params.text("dir", ""), dir, e);
  take(params.text("pace", "recorded"), pace, e);
  take(params.integer("loop", 0, 0, 1), loop, e);
  if (!e.empty()) return err(e);
  if (pace != "recorded" && pace != "max")
    return err("replay_source: pace must be recorded or max, not '" + pace + "'");
  if (*capacity < kinect::DEPTH_PIXELS)
    return err(full_frame_too_large("replay_source", *capacity, context));
  auto index = formats::read_fakenect_index(dir);
  if (!index) return err("replay_source: " + index.error().to_string());
  std::size_t accel_records = 0, unusable = 0;
  auto ups = recorded_ups(dir, *index, accel_records, unusable);
  if (!ups) return err("replay_source: " + ups.error());
  if (unusable > 0)
    std::fprintf(stderr,
                 "replay_source: %zu of %zu accelerometer records skipped (unreadable, or not a "
                 "plausible gravity reading)\n",
                 unusable, accel_records);
  // Depth records in time order: one whose host time is not later than the record before it is
  // skipped and counted, never reordered (the device clock wraps every 72 s; the host's does not).
  std::vector<formats::FakenectEntry> depth;
  std::vector<RecordedUp> depth_ups;
  RecordingStats stats;
  std::size_t d = 0;
  for (auto& entry : *index) {
    if (entry.kind != 'd') continue;
    const RecordedUp up = (*ups)[d++];
    if (!depth.empty() && !(entry.host_seconds > depth.back().host_seconds)) {
      ++stats.out_of_order;
      continue;
    }
    depth.push_back(std::move(entry));
    depth_ups.push_back(up);
  }
  if (stats.out_of_order > 0)
    std::fprintf(stderr,
                 "replay_source: %llu depth records skipped: INDEX.txt lists them after a later "
                 "one\n",
                 static_cast<unsigned long long>(stats.out_of_order));
  stats.frames_missing = frames_missing(depth);
  stats.accel_skipped = unusable;
  for (const RecordedUp& u : depth_ups)
    stats.without_gravity += u.up == std::array<float, 3>{} ? 1U : 0U;
  if (depth.empty()) return err("replay_source: '" + dir + "/INDEX.txt' lists no depth record");
  // device.json is optional in fakenect (older recordings lack it): the typical device then.
  kinect::Calibration calibration;
  if (std::filesystem::exists(std::filesystem::path(dir) / "device.json")) {
    auto device = read_fakenect_device(std::filesystem::path(dir) / "device.json");
    if (!device) return err("replay_source: " + device.error().to_string());
    calibration = *device;
  }
  return std::unique_ptr<engine::Node>(
      new ReplaySource(*capacity, context, std::move(depth), std::move(depth_ups), stats, dir,
                       calibration, pace == "recorded", loop == 1));
}

}  // namespace

void add_replay_source(engine::NodeRegistry& registry) {
  registry.add("replay_source",
               "a fakenect recording's depth (orthoflow kinect record, libfreenect "
               "fakenect-record): dir, pace=recorded|max, loop=0|1",
               make_replay);
}

}  // namespace orthoflow::graphs
