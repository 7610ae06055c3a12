#include "graphs/nodes/replay_source.hpp"

#include <chrono>
#include <thread>

#include "drivers/kinect/kinect_camera.hpp"
#include "drivers/kinect/kinect_depth.hpp"
#include "formats/fakenect.hpp"
#include "formats/file_bytes.hpp"
#include "graphs/nodes/decode_ahead.hpp"
#include "graphs/nodes/fakenect_calibration.hpp"
#include "graphs/nodes/frame_source.hpp"
#include "graphs/nodes/node_support.hpp"
#include "kernels/depth_projection.hpp"

namespace orthoflow::graphs {

namespace {

using engine::Message;
using engine::ParamMap;
using Clock = std::chrono::steady_clock;
namespace kinect = drivers::kinect;

/// The depth records of a fakenect recording (ours or libfreenect's fakenect-record), read and
/// converted ahead on the decoder thread with the same code as the live camera (the device's
/// raw-to-metres table and pinhole, kinect_source), then emitted at the recorded pace (the host
/// times in the file names) or as fast as the graph takes them.
class ReplaySource final : public FrameSource {
 public:
  static constexpr std::chrono::milliseconds DECODE_TIMEOUT{5000};
  static constexpr std::int64_t MAX_GAP_NS = 1'000'000'000;  // a pause in the recording: cut to 1 s

  ReplaySource(std::size_t capacity, const engine::NodeContext& context,
               std::vector<formats::FakenectEntry> entries, std::filesystem::path dir,
               const kinect::Calibration& calibration, bool paced, bool loop)
      : FrameSource(capacity, context),
        entries_(std::move(entries)),
        dir_(std::move(dir)),
        paced_(paced),
        raw_(kinect::DEPTH_PIXELS) {
    kinect::make_depth_table_m(calibration, table_m_);
    camera_ = kinect::depth_camera(calibration);
    std::vector<std::filesystem::path> files;
    for (const auto& e : entries_) files.push_back(dir_ / e.file);
    decoder_ = std::make_unique<DecodeAhead>(
        std::move(files), loop, 3, [this](std::size_t i, DecodeAhead::Slot& s) { decode(i, s); });
  }
  ~ReplaySource() override { decoder_.reset(); }  // the decoder thread uses the members above

  engine::SourceStatus produce(Message& out) noexcept override {
    DecodeAhead::Slot* slot = decoder_->next(DECODE_TIMEOUT);
    if (slot != nullptr && slot->end) return engine::SourceStatus::END;
    if (slot != nullptr && slot->ok && paced_) pace(slot->schedule_ns);
    if (!take_block(out)) return engine::SourceStatus::FRAME;
    if (slot == nullptr || !slot->ok) {
      const FrameBlock block = block_of(out, capacity_);
      (void)engine::write_frame(block.raw(), kernels::PointCloud{});
      new (&block.state()) FrameState{};
      FrameError& e = block.state().error;
      e.set(FrameError::Code::FILE_UNREADABLE, name_,
            slot == nullptr ? 0 : static_cast<std::uint8_t>(slot->error.code));
      e.detail.assign_elided(slot == nullptr
                                 ? std::string_view("replay_source: no record decoded within 5 s")
                                 : std::string_view(slot->error.message));
      return engine::SourceStatus::FRAME;
    }
    kernels::PointCloud& cloud = slot->cloud;
    cloud.info.frame_id = frames_++;
    cloud.info.host_stamp_ns = Clock::now().time_since_epoch().count();
    emit_cloud(out, cloud);
    decoder_->release();
    return engine::SourceStatus::FRAME;
  }

 private:
  /// Decoder thread: one record into @p slot.
  void decode(std::size_t index, DecodeAhead::Slot& slot) {
    const formats::FakenectEntry& e = entries_[index];
    // Errors name the record as INDEX.txt lists it (a frame error's detail is short).
    auto bytes = formats::read_file_bytes(dir_ / e.file, std::size_t{1} << 20);
    auto read = bytes ? formats::parse_fakenect_depth(*bytes, e.file, raw_)
                      : Result<void, formats::IoError>(
                            err(formats::IoError{bytes.error().code, e.file + ": cannot read"}));
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
    slot.schedule_ns = static_cast<std::int64_t>((e.host_seconds - first_seconds_) * 1e9);
    slot.ok = true;
  }

  /// Sleeps until the record's recorded time (relative to the first record emitted).
  void pace(std::int64_t schedule_ns) noexcept {
    const auto now = Clock::now();
    if (!started_ || schedule_ns < last_schedule_ns_) {  // first record, or the loop started over
      started_ = true;
      origin_ = now - std::chrono::nanoseconds(schedule_ns);
    } else if (schedule_ns - last_schedule_ns_ > MAX_GAP_NS) {
      origin_ -= std::chrono::nanoseconds(schedule_ns - last_schedule_ns_ - MAX_GAP_NS);
    }
    last_schedule_ns_ = schedule_ns;
    std::this_thread::sleep_until(origin_ + std::chrono::nanoseconds(schedule_ns));
  }

  std::vector<formats::FakenectEntry> entries_;
  std::filesystem::path dir_;
  bool paced_;
  std::array<float, kernels::DISPARITY_TABLE_SIZE> table_m_{};
  kernels::DepthCamera camera_{};
  std::vector<std::uint16_t> raw_;  // decoder thread only
  double first_seconds_ = 0.0;
  std::uint64_t ticks_ = 0;
  std::uint32_t last_ticks_ = 0;
  bool started_ = false;
  std::int64_t last_schedule_ns_ = 0;
  Clock::time_point origin_{};
  std::uint64_t frames_ = 0;
  std::unique_ptr<DecodeAhead> decoder_;  // last: its thread uses everything above
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
  std::vector<formats::FakenectEntry> depth;
  for (auto& entry : *index) {
    if (entry.kind == 'd') depth.push_back(std::move(entry));
  }
  if (depth.empty()) return err("replay_source: '" + dir + "/INDEX.txt' lists no depth record");
  // device.json is optional in fakenect (older recordings lack it): the typical device then.
  kinect::Calibration calibration;
  if (std::filesystem::exists(std::filesystem::path(dir) / "device.json")) {
    auto device = read_fakenect_device(std::filesystem::path(dir) / "device.json");
    if (!device) return err("replay_source: " + device.error().to_string());
    calibration = *device;
  }
  return std::unique_ptr<engine::Node>(new ReplaySource(
      *capacity, context, std::move(depth), dir, calibration, pace == "recorded", loop == 1));
}

}  // namespace

void add_replay_source(engine::NodeRegistry& registry) {
  registry.add("replay_source",
               "a fakenect recording's depth (orthoflow kinect record, libfreenect "
               "fakenect-record): dir, pace=recorded|max, loop=0|1",
               make_replay);
}

}  // namespace orthoflow::graphs
