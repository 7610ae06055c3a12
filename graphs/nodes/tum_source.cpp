#include "graphs/nodes/tum_source.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <limits>

#include "formats/file_bytes.hpp"
#include "formats/png_depth.hpp"
#include "formats/tum_rgbd.hpp"
#include "graphs/nodes/node_support.hpp"
#include "graphs/nodes/recording_source.hpp"
#include "kernels/depth_projection.hpp"

namespace orthoflow::graphs {

namespace {

using engine::Message;
using engine::ParamMap;

constexpr std::size_t TUM_PIXELS = std::size_t{formats::TUM_WIDTH} * formats::TUM_HEIGHT;

/// Frames missing between consecutive depth images: capture-time gaps of more than one and a half
/// 30 Hz periods, rounded to whole frames.
std::uint64_t frames_missing(const std::vector<formats::TumDepthEntry>& depth) {
  std::uint64_t missing = 0;
  for (std::size_t k = 1; k < depth.size(); ++k) {
    const double periods = (depth[k].seconds - depth[k - 1].seconds) * 30.0;
    if (periods > 1.5)
      missing += static_cast<std::uint64_t>(std::min(std::lround(periods), 1L << 40)) - 1U;
  }
  return missing;
}

/// A 16-bit depth image to an organized cloud: z = value / units_per_metre, x = (u - cx) / fx * z,
/// y = (v - cy) / fy * z; 0 ("no reading") becomes NaN. Scalar: it runs on the decoder thread.
void project_depth_image(std::span<const std::uint16_t> image, double units_per_metre,
                         const kernels::DepthCamera& camera, kernels::PointCloud& cloud) {
  const float inv_units = static_cast<float>(1.0 / units_per_metre);
  const float nan = std::numeric_limits<float>::quiet_NaN();
  auto out = cloud.points();
  for (std::uint32_t v = 0; v < formats::TUM_HEIGHT; ++v) {
    const float ray_y = (static_cast<float>(v) - camera.cy) / camera.fy;
    for (std::uint32_t u = 0; u < formats::TUM_WIDTH; ++u) {
      const std::size_t i = std::size_t{v} * formats::TUM_WIDTH + u;
      const float z = static_cast<float>(image[i]) * inv_units;
      const bool valid = image[i] != 0;
      out.x[i] = valid ? (static_cast<float>(u) - camera.cx) / camera.fx * z : nan;
      out.y[i] = valid ? ray_y * z : nan;
      out.z[i] = valid ? z : nan;
    }
  }
}

class TumSource final : public RecordingSource {
 public:
  TumSource(std::size_t capacity, const engine::NodeContext& context, formats::TumDepthList list,
            std::filesystem::path dir, const kernels::DepthCamera& camera, double units, bool paced,
            bool loop)
      : RecordingSource(capacity, context, paced, "tum_source: no depth image decoded within 5 s"),
        list_(std::move(list)),
        missing_(frames_missing(list_.entries)),
        dir_(std::move(dir)),
        camera_(camera),
        units_(units),
        image_(TUM_PIXELS) {
    std::vector<std::filesystem::path> files;
    for (const auto& e : list_.entries) files.push_back(dir_ / e.file);
    start_decoding(std::move(files), loop,
                   [this](std::size_t i, DecodeAhead::Slot& s) { decode(i, s); });
  }
  ~TumSource() override { stop_decoding(); }  // the decoder thread uses the members below

  /// The recording's account: depth images listed, frames missing between them (capture-time gaps
  /// of more than one 30 Hz period), listing lines skipped as out of time order.
  const char* counter_group() const noexcept override { return "recording"; }
  std::size_t device_counters(std::span<engine::DeviceCounter> out) const noexcept override {
    const std::array<engine::DeviceCounter, 3> all{{{"depth_records", list_.entries.size()},
                                                    {"frames_missing", missing_},
                                                    {"out_of_order", list_.out_of_order}}};
    const std::size_t k = std::min(out.size(), all.size());
    std::copy_n(all.begin(), k, out.begin());
    return k;
  }

 private:
  /// Decoder thread: one depth image into @p slot.
  void decode(std::size_t index, DecodeAhead::Slot& slot) {
    const formats::TumDepthEntry& e = list_.entries[index];
    auto bytes = formats::read_file_bytes(dir_ / e.file, std::size_t{8} << 20);
    auto read =
        bytes ? formats::parse_png_depth16(*bytes, e.file, formats::TUM_WIDTH, formats::TUM_HEIGHT,
                                           image_)
              : Result<void, formats::IoError>(err(formats::IoError{
                    bytes.error().code,
                    e.file + ": " + formats::read_failure_reason(bytes.error(), dir_ / e.file)}));
    if (!read) {
      slot.ok = false;
      slot.error = read.error();
      return;
    }
    slot.cloud.resize(formats::TUM_WIDTH, formats::TUM_HEIGHT);
    project_depth_image(image_, units_, camera_, slot.cloud);
    slot.cloud.info.sensor_stamp_ns = static_cast<std::int64_t>(std::llround(e.seconds * 1e9));
    slot.cloud.info.up = {};  // a TUM folder gives no "up"
    slot.cloud.info.up_age_ms = 0;
    slot.schedule_ns = static_cast<std::int64_t>((e.seconds - list_.entries.front().seconds) * 1e9);
    slot.ok = true;
  }

  formats::TumDepthList list_;
  std::uint64_t missing_;
  std::filesystem::path dir_;
  kernels::DepthCamera camera_;
  double units_;
  std::vector<std::uint16_t> image_;  // decoder thread only
};

NodeResult make_tum(const ParamMap& params, const engine::NodeContext& context) {
  auto capacity = frame_capacity(context);
  if (!capacity) return err(capacity.error());
  if (auto ok = params.only({"dir", "pace", "loop", "fx", "fy", "cx", "cy", "units_per_metre"});
      !ok)
    return err(ok.error());
  std::string dir, pace, e;
  std::int64_t loop = 0;
  double fx = 0, fy = 0, cx = 0, cy = 0, units = 0;
  take(params.text("dir", ""), dir, e);
  take(params.text("pace", "recorded"), pace, e);
  take(params.integer("loop", 0, 0, 1), loop, e);
  take(params.number("fx", 525.0, 1.0, 1.0e5), fx, e);
  take(params.number("fy", 525.0, 1.0, 1.0e5), fy, e);
  take(params.number("cx", 319.5, -1.0e4, 1.0e4), cx, e);
  take(params.number("cy", 239.5, -1.0e4, 1.0e4), cy, e);
  take(params.number("units_per_metre", formats::TUM_DEPTH_UNITS_PER_METRE, 1.0, 1.0e6), units, e);
  if (!e.empty()) return err(e);
  if (pace != "recorded" && pace != "max")
    return err("tum_source: pace must be recorded or max, not '" + pace + "'");
  if (*capacity < TUM_PIXELS) return err(full_frame_too_large("tum_source", *capacity, context));
  auto list = formats::read_tum_depth_list(dir);
  if (!list) return err("tum_source: " + list.error().to_string());
  if (list->out_of_order > 0)
    std::fprintf(stderr, "tum_source: %zu lines of %s skipped: not later than the line before\n",
                 list->out_of_order, list->listing.c_str());
  const kernels::DepthCamera camera{static_cast<float>(fx), static_cast<float>(fy),
                                    static_cast<float>(cx), static_cast<float>(cy)};
  return std::unique_ptr<engine::Node>(new TumSource(*capacity, context, std::move(*list), dir,
                                                     camera, units, pace == "recorded", loop == 1));
}

}  // namespace

void add_tum_source(engine::NodeRegistry& registry) {
  registry.add(
      "tum_source",
      "a TUM RGB-D benchmark folder's depth (associate.txt or depth.txt, 16-bit PNG): dir, "
      "pace=recorded|max, loop=0|1, fx, fy, cx, cy, units_per_metre (5000)",
      make_tum);
}

}  // namespace orthoflow::graphs
