#include "graphs/services/session_log.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace orthoflow::graphs {

namespace {
constexpr std::size_t SNAPSHOT_POINTS = 40000;
constexpr std::size_t LINE_BYTES = 1 << 18;
constexpr std::size_t MAX_TAUGHT = 1024;
}  // namespace

SessionLog::SessionLog(std::unique_ptr<LineWriter> json)
    : json_(std::move(json)), line_(LINE_BYTES) {
  summary_.taught.reserve(MAX_TAUGHT);
  taught_instances_.reserve(MAX_TAUGHT);
  snapshot_.hull_u.reserve(MAX_HULL);
  snapshot_.hull_v.reserve(MAX_HULL);
  snapshot_.x.reserve(SNAPSHOT_POINTS);
  snapshot_.y.reserve(SNAPSHOT_POINTS);
  snapshot_.z.reserve(SNAPSHOT_POINTS);
  snapshot_.objects.reserve(MAX_OBJECTS);
}

bool SessionLog::was_taught(std::string_view category) const noexcept {
  return std::find(summary_.taught.begin(), summary_.taught.end(), category) !=
         summary_.taught.end();
}

void SessionLog::score(const ObjectRecord& o) noexcept {
  if (!o.recognised) return;
  ++summary_.recognitions;
  if (o.truth_category.empty()) return;
  const std::string_view truth = o.truth_category.view();
  if (!was_taught(truth)) {
    summary_.before_teaching.right += o.unknown ? 1U : 0U;
    ++summary_.before_teaching.asked;
    return;
  }
  const bool right = !o.unknown && o.label.view() == truth;
  summary_.after_teaching.right += right ? 1U : 0U;
  ++summary_.after_teaching.asked;
  if (std::find(taught_instances_.begin(), taught_instances_.end(), o.truth_label) ==
      taught_instances_.end()) {
    summary_.new_instances.right += right ? 1U : 0U;
    ++summary_.new_instances.asked;
  }
}

void SessionLog::record(const FrameBlock& block, std::uint64_t frame_id) noexcept {
  const FrameState& s = block.state();
  ++summary_.frames;
  summary_.frames_with_table += s.table_found ? 1U : 0U;
  summary_.frames_with_error += s.error.empty() ? 0U : 1U;
  if (!s.error.empty() && summary_.first_error.empty()) {
    summary_.first_error = s.error;
    summary_.first_error_frame = frame_id;
  }
  summary_.object_views += s.object_count;
  for (std::uint32_t k = 0; k < s.object_count; ++k) {
    const ObjectRecord& o = s.objects[k];
    summary_.key_views += o.key_view ? 1U : 0U;
    summary_.tracks_started = std::max(summary_.tracks_started, o.track_id);
    score(o);  // scored before this frame's teach counts: the answer came before the lesson
  }
  for (std::uint32_t k = 0; k < s.object_count; ++k) {
    const ObjectRecord& o = s.objects[k];
    if (!o.taught) continue;
    ++summary_.teaches;
    // Bounded by the reserved capacity: past it, lessons are still counted but not listed.
    if (!was_taught(o.taught_as.view()) && summary_.taught.size() < MAX_TAUGHT)
      summary_.taught.emplace_back(o.taught_as.view());
    if (taught_instances_.size() < MAX_TAUGHT) taught_instances_.push_back(o.truth_label);
  }
  if (json_) write_json(block, frame_id);
  if (s.object_count > 0) keep_snapshot(block, frame_id);
}

namespace {

/// `"plane":{...},"objects":[` (the plane null when the frame has none): the table plane (normal .
/// p + d = 0, sensor frame, metres), its inlier count on the dense sample and how sure the table
/// stage is of it (kernels::PlaneCheck). @return the characters written.
std::size_t write_plane(const FrameState& s, char* out, std::size_t cap) noexcept {
  if (!s.table_found)
    return static_cast<std::size_t>(std::snprintf(out, cap, R"("plane":null,"objects":[)"));
  const auto& n = s.plane.normal;
  const kernels::PlaneCheck& c = s.plane_check;
  const auto finite = [](float v) { return std::isfinite(v) ? static_cast<double>(v) : 0.0; };
  return static_cast<std::size_t>(std::snprintf(
      out, cap,
      R"("plane":{"normal":[%.6f,%.6f,%.6f],"d":%.6f,"inliers":%u,"near_share":%.4f,"rms_m":%.6f,"switched":%s},"objects":[)",
      finite(n[0]), finite(n[1]), finite(n[2]), finite(s.plane.d), s.plane_inliers,
      finite(c.near_share), finite(c.rms_m), c.switched ? "true" : "false"));
}

}  // namespace

void SessionLog::write_json(const FrameBlock& block, std::uint64_t frame_id) noexcept {
  const FrameState& s = block.state();
  auto frame = block.frame();
  const std::int64_t stamp = frame ? frame->header->sensor_stamp_ns : 0;
  char* out = line_.data();
  const std::size_t cap = line_.size();
  const std::string_view verdict = kernels::table_reason_name(s.table_reason);
  const std::string_view gravity = gravity_name(s.gravity);
  char tilt[24] = "null";  // the own plane's angle from up: known only with a plane and an up
  if (std::isfinite(s.judged.tilt_deg) && s.judged.height_m > 0.0F)
    std::snprintf(tilt, sizeof tilt, "%.2f", static_cast<double>(s.judged.tilt_deg));
  std::size_t n = static_cast<std::size_t>(std::snprintf(
      out, cap,
      R"({"frame":%llu,"stamp_ns":%lld,"table":%s,"table_reason":"%.*s","gravity":"%.*s","tilt_deg":%s,)",
      static_cast<unsigned long long>(frame_id), static_cast<long long>(stamp),
      s.table_found ? "true" : "false", static_cast<int>(verdict.size()), verdict.data(),
      static_cast<int>(gravity.size()), gravity.data(), tilt));
  if (s.up_stale_ms > 0)  // the sensor's up was refused as too old: why gravity is not "sensor"
    n += static_cast<std::size_t>(
        std::snprintf(out + n, cap - n, R"("up_stale_ms":%u,)", s.up_stale_ms));
  if (s.judged.height_m > 0.0F)  // what the verdict measured on this frame's own plane
    n += static_cast<std::size_t>(std::snprintf(
        out + n, cap - n, R"("support":{"share":%.4f,"area_m2":%.4f,"height_m":%.4f},)",
        static_cast<double>(s.judged.share), static_cast<double>(s.judged.area_m2),
        static_cast<double>(s.judged.height_m)));
  n += static_cast<std::size_t>(std::snprintf(  // what the objects stage's budget spared
      out + n, cap - n,
      R"("budget":{"prism_points":%u,"stride":%u,"refined":%s,"far_dropped":%u},)", s.prism_points,
      static_cast<unsigned>(s.stride), s.refined ? "true" : "false", s.rejected_capacity));
  n += write_plane(s, out + n, cap - n);
  for (std::uint32_t k = 0; k < s.object_count && n + 2048 < cap; ++k) {
    const ObjectRecord& o = s.objects[k];
    // Labels are category names given by people: escape nothing but refuse quotes/backslashes in
    // them.
    const std::string_view label = o.label.view();
    const bool plain = label.find_first_of("\"\\") == std::string_view::npos;
    char score[32] = "null";  // JSON has no NaN: nothing learned yet gives a NaN score
    if (std::isfinite(o.score))
      std::snprintf(score, sizeof score, "%.6g", static_cast<double>(o.score));
    n += static_cast<std::size_t>(std::snprintf(
        out + n, cap - n,
        R"(%s{"track":%u,"label":%s%.*s%s,"unknown":%s,"carried":%s,"score":%s,"nearest":"%.*s","truth":"%.*s","points":%u,"centroid":[%.5f,%.5f,%.5f],"bbox":[%.5f,%.5f,%.5f],"frame":[)",
        k == 0 ? "" : ",", o.track_id, o.unknown || !plain ? "null" : "\"",
        o.unknown || !plain ? 0 : static_cast<int>(label.size()), label.data(),
        o.unknown || !plain ? "" : "\"", o.unknown ? "true" : "false", o.carried ? "true" : "false",
        score, plain ? static_cast<int>(o.nearest.view().size()) : 0, o.nearest.view().data(),
        static_cast<int>(o.truth_category.view().size()), o.truth_category.view().data(), o.count,
        static_cast<double>(o.stats.centroid[0]), static_cast<double>(o.stats.centroid[1]),
        static_cast<double>(o.stats.centroid[2]), static_cast<double>(o.bbox[0]),
        static_cast<double>(o.bbox[1]), static_cast<double>(o.bbox[2])));
    for (std::size_t i = 0; i < 16; ++i) {
      n += static_cast<std::size_t>(std::snprintf(out + n, cap - n, "%s%.6g", i == 0 ? "" : ",",
                                                  static_cast<double>(o.frame[i])));
    }
    n += static_cast<std::size_t>(std::snprintf(out + n, cap - n, "]}"));
  }
  n += static_cast<std::size_t>(std::snprintf(out + n, cap - n, "]"));
  if (!s.error.empty() &&
      n + 256 < cap) {  // the frame's first error: node, code and the stage's reason
    const std::string_view stage = s.error.stage.view(), code = FrameError::name(s.error.code);
    const std::string_view reason = s.error.code == FrameError::Code::SEGMENTATION
                                        ? kernels::to_string(s.error.segmentation.code)
                                        : std::string_view{};
    const bool plain = stage.find_first_of("\"\\") == std::string_view::npos;
    n += static_cast<std::size_t>(
        std::snprintf(out + n, cap - n, R"(,"error":"%.*s%s%.*s%s%.*s")",
                      plain ? static_cast<int>(stage.size()) : 0, stage.data(), plain ? ": " : "",
                      static_cast<int>(code.size()), code.data(), reason.empty() ? "" : ": ",
                      static_cast<int>(reason.size()), reason.data()));
  }
  n += static_cast<std::size_t>(std::snprintf(out + n, cap - n, "}"));
  json_->write({out, std::min(n, cap - 1)});
}

void SessionLog::keep_snapshot(const FrameBlock& block, std::uint64_t frame_id) noexcept {
  const FrameState& s = block.state();
  SceneSnapshot& snap = snapshot_;
  snap.valid = true;
  snap.frame_id = frame_id;
  snap.plane = s.plane;
  snap.hull_u.assign(block.hull_u().begin(), block.hull_u().begin() + s.hull_count);
  snap.hull_v.assign(block.hull_v().begin(), block.hull_v().begin() + s.hull_count);
  snap.objects.assign(s.objects.begin(), s.objects.begin() + s.object_count);
  std::size_t total = 0;
  for (const ObjectRecord& o : snap.objects) total += o.count;
  const std::size_t step = total / SNAPSHOT_POINTS + 1;
  snap.x.clear();
  snap.y.clear();
  snap.z.clear();
  const kernels::PointsSpan p = block.object_points();
  for (std::size_t i = 0; i < total; i += step) {
    snap.x.push_back(p.x[i]);
    snap.y.push_back(p.y[i]);
    snap.z.push_back(p.z[i]);
  }
}

}  // namespace orthoflow::graphs
