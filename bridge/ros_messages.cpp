#include "bridge/ros_messages.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstring>

#include <Eigen/Geometry>

#include "core/label_text.hpp"
#include "graphs/frame/frame_block.hpp"
#include "kernels/table_verdict.hpp"

namespace orthoflow::bridge {
namespace {

constexpr std::uint32_t POINT_STEP = 16;

void copy_text(std::string_view text, std::span<char> out) noexcept {
  const std::size_t n = std::min(text.size(), out.size() - 1);
  if (n > 0) std::memcpy(out.data(), text.data(), n);
  out[n] = '\0';
}

// The entry's pose as camera_from_object: its frame is object_from_camera, row-major, rotation rows
// the object's axes in the camera. @return false when it is not a finite rigid transform.
bool camera_from_object(const engine::ObjectEntry& e, Eigen::Isometry3d& out) noexcept {
  Eigen::Matrix4d m;
  for (int r = 0; r < 4; ++r)
    for (int c = 0; c < 4; ++c) m(r, c) = e.frame[4 * r + c];
  if (!m.allFinite()) return false;
  const Eigen::Matrix3d r = m.topLeftCorner<3, 3>();
  if (!(r * r.transpose()).isApprox(Eigen::Matrix3d::Identity(), 1e-3) ||
      std::fabs(r.determinant() - 1.0) > 1e-3)
    return false;
  out.linear() = r.transpose();
  out.translation() = -r.transpose() * m.topRightCorner<3, 1>();
  return true;
}

}  // namespace

StampClock::StampClock() noexcept {
  const auto system = std::chrono::system_clock::now().time_since_epoch();
  const auto steady = std::chrono::steady_clock::now().time_since_epoch();
  offset_ns_ = std::chrono::duration_cast<std::chrono::nanoseconds>(system - steady).count();
}

void to_ros_time(std::int64_t ns, builtin_interfaces_msg_dds__Time_& out) noexcept {
  std::int64_t sec = ns / 1'000'000'000;
  std::int64_t rest = ns % 1'000'000'000;
  if (rest < 0) {
    rest += 1'000'000'000;
    --sec;
  }
  out.sec = static_cast<std::int32_t>(std::clamp<std::int64_t>(sec, INT32_MIN, INT32_MAX));
  out.nanosec = static_cast<std::uint32_t>(rest);
}

std::int64_t from_ros_time(const builtin_interfaces_msg_dds__Time_& t) noexcept {
  return std::int64_t{t.sec} * 1'000'000'000 + std::int64_t{t.nanosec};
}

RosScratch::RosScratch()
    : objects(engine::OBJECT_LIST_CAPACITY), labels(engine::OBJECT_LIST_CAPACITY) {
  copy_text("camera_depth_optical_frame", camera_frame);
  static constexpr std::array<const char*, 4> NAMES{"x", "y", "z", "rgb"};
  for (std::size_t i = 0; i < fields.size(); ++i) {
    fields[i].name = const_cast<char*>(NAMES[i]);  // read only: Cyclone serialises from it
    fields[i].offset = static_cast<std::uint32_t>(4 * i);
    fields[i].datatype = static_cast<std::uint8_t>(PointFieldType::FLOAT32);
    fields[i].count = 1;
  }
}

std::size_t to_ros(const engine::ObjectListPayload& list, const StampClock& clock,
                   RosScratch& scratch, RosObjectArray& out) noexcept {
  to_ros_time(clock.system_ns(list.host_stamp_ns), out.header.stamp);
  out.header.frame_id = scratch.camera_frame.data();
  out.frame_number = list.frame_id;
  out.age_ns = list.age_ns;
  // The table verdict (issue 50): the names are string literals, so their data() ends in a NUL.
  static constexpr char NOT_REPORTED[] = "";
  const bool reason_known = list.table_reason >= 1 && list.table_reason <= 6;
  const auto reason = static_cast<kernels::TableReason>(list.table_reason - 1);
  out.table = reason_known &&
              (reason == kernels::TableReason::ACCEPTED || reason == kernels::TableReason::HELD);
  out.table_reason =
      const_cast<char*>(reason_known ? kernels::table_reason_name(reason).data() : NOT_REPORTED);
  const bool gravity_known = list.gravity >= 1 && list.gravity <= 3;
  out.gravity = const_cast<char*>(
      gravity_known ? graphs::gravity_name(static_cast<graphs::Gravity>(list.gravity - 1)).data()
                    : NOT_REPORTED);
  const std::size_t n = std::min<std::size_t>(list.count, engine::OBJECT_LIST_CAPACITY);
  for (std::size_t i = 0; i < n; ++i) {
    const engine::ObjectEntry& e = list.objects[i];
    RosObject& o = scratch.objects[i];
    o = RosObject{};
    copy_text(e.label.view(), scratch.labels[i]);
    o.track_id = e.track_id;
    o.label = scratch.labels[i].data();
    o.unknown = e.unknown != 0;
    o.score = e.score;
    o.centroid = {e.centroid[0], e.centroid[1], e.centroid[2]};
    o.point_count = e.point_count;
    o.flags = e.flags;
    o.pose.orientation.w = 1.0;
    Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
    const bool sized =
        std::isfinite(e.bbox[0]) && std::isfinite(e.bbox[1]) && std::isfinite(e.bbox[2]);
    if ((e.flags & engine::OBJECT_DESCRIBED) != 0 && sized && camera_from_object(e, pose)) {
      const Eigen::Quaterniond q = Eigen::Quaterniond(pose.linear()).normalized();
      o.pose.position = {pose.translation().x(), pose.translation().y(), pose.translation().z()};
      o.pose.orientation = {q.x(), q.y(), q.z(), q.w()};
      o.size = {e.bbox[0], e.bbox[1], e.bbox[2]};
    } else {
      o.flags &= ~engine::OBJECT_DESCRIBED;
    }
  }
  out.objects._maximum = static_cast<std::uint32_t>(n);
  out.objects._length = static_cast<std::uint32_t>(n);
  out.objects._buffer = scratch.objects.data();
  out.objects._release = false;
  return n;
}

std::size_t to_ros(const engine::FrameView& frame, const StampClock& clock, RosScratch& scratch,
                   RosPointCloud2& out) {
  const engine::FrameHeader& h = *frame.header;
  const kernels::PointsView p = frame.cloud.points;
  const std::size_t n = p.size();
  const bool colour = frame.rgb.size() == n && n > 0;
  const std::size_t bytes = n * POINT_STEP;
  if (scratch.cloud.size() < bytes) scratch.cloud.resize(bytes);
  std::uint8_t* data = scratch.cloud.data();
  bool dense = true;
  for (std::size_t i = 0; i < n; ++i) {
    const float xyz[3] = {p.x[i], p.y[i], p.z[i]};
    const std::uint32_t rgb = colour ? (frame.rgb[i] & 0x00FFFFFFU) : 0U;
    std::memcpy(data + i * POINT_STEP, xyz, sizeof xyz);
    std::memcpy(data + i * POINT_STEP + 12, &rgb, sizeof rgb);
    dense = dense && std::isfinite(xyz[0]) && std::isfinite(xyz[1]) && std::isfinite(xyz[2]);
  }
  to_ros_time(clock.system_ns(h.host_stamp_ns), out.header.stamp);
  out.header.frame_id = scratch.camera_frame.data();
  const bool organized = frame.cloud.organized();
  out.height = organized ? frame.cloud.height : 1U;
  out.width = organized ? frame.cloud.width : static_cast<std::uint32_t>(n);
  const std::uint32_t field_count = colour ? 4U : 3U;
  out.fields = {field_count, field_count, scratch.fields.data(), false};
  out.is_bigendian = false;
  out.point_step = POINT_STEP;
  out.row_step = POINT_STEP * out.width;
  out.data = {static_cast<std::uint32_t>(bytes), static_cast<std::uint32_t>(bytes), data, false};
  out.is_dense = dense;
  return bytes;
}

Result<graphs::LearningCommandPayload, CommandRefusal> from_ros(const RosLearningCommand& command,
                                                                std::uint64_t client,
                                                                std::uint64_t request) noexcept {
  using Kind = graphs::LearningCommand::Kind;
  if (command.client == 0)
    return err(CommandRefusal{255, "client 0: a sender needs a non-zero id to get its ack"});
  if (command.kind > static_cast<std::uint8_t>(Kind::UNDO))
    return err(CommandRefusal{255, "kind " + std::to_string(command.kind) + " is not one of 0..4"});
  graphs::LearningCommand c;
  c.kind = static_cast<Kind>(command.kind);
  c.track_id = command.track_id;
  c.by_position = command.by_position;
  c.position = {static_cast<float>(command.position.x), static_cast<float>(command.position.y),
                static_cast<float>(command.position.z)};
  const std::string_view label =
      command.label == nullptr ? std::string_view{} : std::string_view(command.label);
  const bool needs_label =
      c.kind == Kind::TEACH || c.kind == Kind::CORRECT || c.kind == Kind::FORGET;
  if (needs_label) {
    // The whole DDS string, before the payload's 63 bytes could cut it.
    if (const core::LabelProblem p = core::check_label(label); p != core::LabelProblem::NONE)
      return err(CommandRefusal{static_cast<std::uint32_t>(p), std::string(core::to_string(p))});
    c.label.assign(label);
  }
  graphs::LearningCommandPayload payload{};
  if (!graphs::encode_command(c, client, request, payload))
    return err(CommandRefusal{255, "the command does not encode"});
  // The same check the graph makes on every command it receives (and the teaching page's).
  auto checked = graphs::decode_command(
      std::as_bytes(std::span<const graphs::LearningCommandPayload, 1>(&payload, 1)));
  if (!checked) return err(CommandRefusal{checked.error().problem, checked.error().message});
  return payload;
}

void to_ros(const graphs::RemoteAck& ack, std::uint64_t client, std::uint64_t request,
            std::string_view problem_text, AckScratch& scratch, RosLearningAck& out) noexcept {
  out = RosLearningAck{};
  out.client = client;
  out.request = request;
  out.status = static_cast<std::uint8_t>(ack.status);
  copy_text(ack.status == graphs::AckStatus::ACKNOWLEDGED ? graphs::to_string(ack.ack.outcome) : "",
            scratch.outcome);
  copy_text(problem_text, scratch.problem);
  copy_text(ack.ack.label.view(), scratch.label);
  out.outcome = scratch.outcome.data();
  out.problem = scratch.problem.data();
  out.label = scratch.label.data();
  out.kind = static_cast<std::uint8_t>(ack.ack.kind);
  out.track_id = ack.ack.track_id;
  out.score = ack.ack.score;
  out.unknown = ack.ack.unknown;
  out.views = static_cast<std::uint32_t>(ack.ack.views);
}

}  // namespace orthoflow::bridge
