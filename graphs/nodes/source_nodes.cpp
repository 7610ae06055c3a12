#include "graphs/nodes/source_nodes.hpp"

#include <algorithm>
#include <array>
#include <atomic>
#include <chrono>
#include <filesystem>
#include <new>
#include <vector>

#include "formats/pcd_io.hpp"
#include "graphs/nodes/frame_source.hpp"
#include "graphs/nodes/node_support.hpp"
#include "graphs/nodes/session_script.hpp"
#include "kernels/pinhole_regrid.hpp"
#include "simulation/world/object_catalog.hpp"

namespace orthoflow::graphs {

void read_pcd_into(const std::filesystem::path& file, DecodeAhead::Slot& slot) {
  auto cloud = formats::read_pcd(file);
  slot.ok = static_cast<bool>(cloud);
  if (cloud) {
    slot.cloud = std::move(*cloud);
  } else {
    slot.error = cloud.error();
  }
}

namespace {

using engine::Message;
using engine::ParamMap;
using Clock = std::chrono::steady_clock;

class SyntheticSource final : public FrameSource {
 public:
  SyntheticSource(std::size_t capacity, const engine::NodeContext& context,
                  simulation::SequenceScript script, std::uint64_t seed)
      : FrameSource(capacity, context), sequence_(std::move(script), seed) {
    cloud_.reserve(640 * 480);
  }
  engine::SourceStatus produce(Message& out) noexcept override {
    if (!sequence_.next(cloud_)) return engine::SourceStatus::END;
    if (!take_block(out)) return engine::SourceStatus::FRAME;
    cloud_.info.host_stamp_ns = Clock::now().time_since_epoch().count();
    take_up(cloud_, sequence_.scene().table);
    emit_cloud(out, cloud_);
    write_truth(out, sequence_.scene().objects);
    return engine::SourceStatus::FRAME;
  }

 private:
  simulation::SyntheticSequence sequence_;
  kernels::PointCloud cloud_;
};

/// The files of a folder in name order, decoded ahead on the DecodeAhead's thread (reading a
/// binary_compressed frame takes about 8 ms: off the critical path). A file that is not ready
/// within DECODE_TIMEOUT is a frame error, not a hang.
class PcdSource final : public FrameSource {
 public:
  static constexpr std::chrono::milliseconds DECODE_TIMEOUT{5000};
  PcdSource(std::size_t capacity, const engine::NodeContext& context,
            std::vector<std::filesystem::path> files, bool loop, bool organize)
      : FrameSource(capacity, context),
        decoder_(files, loop, 3,
                 [this, files, organize](std::size_t index, DecodeAhead::Slot& slot) {
                   read_pcd_into(files[index], slot);
                   if (slot.ok && organize && !slot.cloud.organized()) organize_cloud(slot.cloud);
                 }) {}
  const char* counter_group() const noexcept override { return "decode"; }
  std::size_t device_counters(std::span<engine::DeviceCounter> out) const noexcept override {
    const std::array<engine::DeviceCounter, 2> all{{
        {"regridded", regridded_.load(std::memory_order_relaxed)},
        {"left_unorganized", left_unorganized_.load(std::memory_order_relaxed)},
    }};
    const std::size_t k = std::min(out.size(), all.size());
    std::copy_n(all.begin(), k, out.begin());
    return k;
  }
  engine::SourceStatus produce(Message& out) noexcept override {
    DecodeAhead::Slot* slot = decoder_.next(DECODE_TIMEOUT);
    if (slot != nullptr && slot->end) return engine::SourceStatus::END;
    const std::uint64_t index = frame_++;
    if (!take_block(out)) return engine::SourceStatus::FRAME;  // the file is skipped with the frame
    if (slot == nullptr || !slot->ok) {  // a bad file is an empty frame with its error
      emit_decode_failure(out, slot,
                          "pcd_source: the decoder did not deliver the next file within 5 s");
      return engine::SourceStatus::FRAME;
    }
    kernels::PointCloud& cloud = slot->cloud;  // ours until release()
    cloud.info.frame_id = index;
    if (cloud.info.sensor_stamp_ns == 0)
      cloud.info.sensor_stamp_ns = static_cast<std::int64_t>(index) * 33'333'333;
    cloud.info.host_stamp_ns = Clock::now().time_since_epoch().count();
    emit_cloud(out, cloud);
    decoder_.release();
    return engine::SourceStatus::FRAME;
  }

 private:
  /// On the decoder thread: an unorganized cloud that a pinhole camera took goes back on its pixel
  /// grid (kernels/pinhole_regrid.hpp), so it takes the organized chain; any other stays as it is,
  /// and so does one whose grid would not fit the pool block.
  void organize_cloud(kernels::PointCloud& cloud) {
    auto& counter = kernels::organize_if_pinhole(cloud, capacity_) ? regridded_ : left_unorganized_;
    counter.fetch_add(1, std::memory_order_relaxed);
  }
  std::atomic<std::uint64_t> regridded_{0}, left_unorganized_{0};  // before decoder_: its thread
  DecodeAhead decoder_;
  std::uint64_t frame_ = 0;
};

NodeResult make_synthetic(const ParamMap& params, const engine::NodeContext& context) {
  auto capacity = frame_capacity(context);
  if (!capacity) return err(capacity.error());
  if (auto ok = params.only({"seed", "frames", "objects"}); !ok) return err(ok.error());
  std::uint64_t seed = 7, frames = SESSION_FRAMES, objects = 0;
  std::string e;
  take(params.integer("seed", 7, 0, INT64_MAX), seed, e);
  take(params.integer("frames", static_cast<std::int64_t>(SESSION_FRAMES), 1, 100'000'000), frames,
       e);
  take(params.integer("objects", 0, 0, simulation::MAX_SCENE_OBJECTS), objects, e);
  if (!e.empty()) return err(e);
  if (*capacity < 640 * 480)
    return err(full_frame_too_large("synthetic_source", *capacity, context));
  auto script = objects == 0 ? make_session_script(frames, seed)
                             : simulation::make_sequence_script(static_cast<std::uint32_t>(objects),
                                                                frames, seed);
  return std::unique_ptr<engine::Node>(
      new SyntheticSource(*capacity, context, std::move(script), seed));
}

NodeResult make_pcd(const ParamMap& params, const engine::NodeContext& context) {
  auto capacity = frame_capacity(context);
  if (!capacity) return err(capacity.error());
  if (auto ok = params.only({"dir", "loop", "organize"}); !ok) return err(ok.error());
  std::string dir, e;
  std::int64_t loop = 0, organize = 1;
  take(params.text("dir", ""), dir, e);
  take(params.integer("loop", 0, 0, 1), loop, e);
  take(params.integer("organize", 1, 0, 1), organize, e);
  if (!e.empty()) return err(e);
  std::error_code ec;
  std::vector<std::filesystem::path> files;
  for (const auto& entry : std::filesystem::directory_iterator(dir, ec)) {
    if (entry.path().extension() == ".pcd") files.push_back(entry.path());
  }
  if (ec) return err("pcd_source: cannot list '" + dir + "': " + ec.message());
  if (files.empty()) return err("pcd_source: no .pcd files in '" + dir + "'");
  std::sort(files.begin(), files.end());
  return std::unique_ptr<engine::Node>(
      new PcdSource(*capacity, context, std::move(files), loop == 1, organize == 1));
}

}  // namespace

void add_source_nodes(engine::NodeRegistry& registry) {
  registry.add("synthetic_source",
               "synthetic Kinect v1 frames: seed, frames, objects (0 = embedded session)",
               make_synthetic);
  registry.add("pcd_source",
               "the .pcd files of a folder in name order: dir, loop=0|1, organize=0|1 (put "
               "unorganized camera-frame clouds back on their pixel grid; default 1)",
               make_pcd);
}

}  // namespace orthoflow::graphs
