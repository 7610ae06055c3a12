#pragma once
/// @file
/// @brief orthoflow's payloads as ROS 2 messages, and back (issue 23). The message types are the
/// C structs idlc generates from bridge/idl (ROS 2's layouts and type names, docs/DDS.md); these
/// functions fill them from the engine's payloads without allocating: every pointer a filled
/// message holds points into a RosScratch the caller keeps (Cyclone serialises from it on write).
///
/// Frames: the pose of an object is camera_from_object, in the camera frame named by
/// BridgeNames::camera_frame; stamps are the system clock (ROS time) of the steady stamps the graph
/// sets, converted by a StampClock.
#include <array>
#include <cstddef>
#include <cstdint>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "core/result.hpp"
#include "engine/frame_payload.hpp"
#include "engine/object_list_payload.hpp"
#include "graphs/channels/learning_payloads.hpp"
#include "orthoflow_msgs/msg/ArmStop.h"
#include "orthoflow_msgs/msg/ArmStopAck.h"
#include "orthoflow_msgs/msg/LearningAck.h"
#include "orthoflow_msgs/msg/LearningCommand.h"
#include "orthoflow_msgs/msg/ObjectArray.h"
#include "sensor_msgs/msg/PointCloud2.h"

namespace orthoflow::bridge {

using RosObjectArray = orthoflow_msgs_msg_dds__ObjectArray_;
using RosObject = orthoflow_msgs_msg_dds__Object_;
using RosPointCloud2 = sensor_msgs_msg_dds__PointCloud2_;
using RosPointField = sensor_msgs_msg_dds__PointField_;
using RosLearningCommand = orthoflow_msgs_msg_dds__LearningCommand_;
using RosLearningAck = orthoflow_msgs_msg_dds__LearningAck_;
using RosArmStop = orthoflow_msgs_msg_dds__ArmStop_;
using RosArmStopAck = orthoflow_msgs_msg_dds__ArmStopAck_;

/// @brief sensor_msgs/PointField's datatype constants (not on the wire; PointField.msg).
enum class PointFieldType : std::uint8_t {
  INT8 = 1,
  UINT8 = 2,
  INT16 = 3,
  UINT16 = 4,
  INT32 = 5,
  UINT32 = 6,
  FLOAT32 = 7,
  FLOAT64 = 8
};

/// @brief The steady clock's stamps as the system clock's (ROS time): one offset, measured once.
class StampClock {
 public:
  /// @brief Measures the offset now.
  StampClock() noexcept;
  /// @brief A clock with a given offset (tests).
  explicit StampClock(std::int64_t system_minus_steady_ns) noexcept
      : offset_ns_(system_minus_steady_ns) {}
  [[nodiscard]] std::int64_t system_ns(std::int64_t steady_ns) const noexcept {
    return steady_ns + offset_ns_;
  }

 private:
  std::int64_t offset_ns_ = 0;
};

/// @brief builtin_interfaces/Time of @p ns (ROS's split: sec may be negative, nanosec in [0, 1e9)).
void to_ros_time(std::int64_t ns, builtin_interfaces_msg_dds__Time_& out) noexcept;
/// @brief The inverse of to_ros_time.
[[nodiscard]] std::int64_t from_ros_time(const builtin_interfaces_msg_dds__Time_& t) noexcept;

/// @brief Storage the filled messages point into. Sized once (no allocation per message after).
struct RosScratch {
  RosScratch();
  std::array<char, 128> camera_frame{};
  std::vector<RosObject> objects;            ///< OBJECT_LIST_CAPACITY entries
  std::vector<std::array<char, 64>> labels;  ///< one per object
  std::array<RosPointField, 4> fields{};     ///< x y z rgb
  std::vector<std::uint8_t> cloud;           ///< point_step x points, grown to the largest
};

/// @brief Fills @p out from the object list @p list (at most OBJECT_LIST_CAPACITY entries are
/// read; a count above it is clamped). An entry whose frame or box is not finite keeps its centroid
/// and label but gets the identity pose, a zero size and no DESCRIBED flag: never a wrong pose.
/// @return the number of entries written. No allocation.
std::size_t to_ros(const engine::ObjectListPayload& list, const StampClock& clock,
                   RosScratch& scratch, RosObjectArray& out) noexcept;

/// @brief Fills @p out from the frame @p frame: organized (height x width), fields x y z (FLOAT32,
/// offsets 0 4 8) and, when the frame has colour, rgb (FLOAT32 at 12, the packed 0x00RRGGBB bits
/// ROS drivers publish); point_step 16, little-endian; invalid points NaN and is_dense false then.
/// @return the data bytes written. Allocates only when the frame is larger than any before it.
std::size_t to_ros(const engine::FrameView& frame, const StampClock& clock, RosScratch& scratch,
                   RosPointCloud2& out);

/// @brief Why a LearningCommand from DDS was refused before it reached the graph.
struct CommandRefusal {
  std::uint32_t problem = 0;  ///< as LearningAckPayload::problem (core::LabelProblem, 254, 255)
  std::string message;
};

/// @brief A LearningCommand from DDS as the graph's payload, addressed from @p client / @p request
/// (the bridge's own ids). The payload then passes graphs::decode_command, the validation every
/// learning command passes (the teaching page's too): kind, label rule, finite position.
/// Refused first: a zero client id (acks could not be routed back), a null or over-long label.
[[nodiscard]] Result<graphs::LearningCommandPayload, CommandRefusal> from_ros(
    const RosLearningCommand& command, std::uint64_t client, std::uint64_t request) noexcept;

/// @brief Storage of a LearningAck's strings.
struct AckScratch {
  std::array<char, 32> outcome{};
  std::array<char, 128> problem{};
  std::array<char, 64> label{};
};

/// @brief Fills @p out from the graph's answer @p ack, addressed back to the DDS sender
/// (@p client, @p request). @p problem_text: words for an INVALID one ("" for the graph's own).
void to_ros(const graphs::RemoteAck& ack, std::uint64_t client, std::uint64_t request,
            std::string_view problem_text, AckScratch& scratch, RosLearningAck& out) noexcept;

}  // namespace orthoflow::bridge
