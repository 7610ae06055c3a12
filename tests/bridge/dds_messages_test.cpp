// The DDS bridge's pieces without a network (issue 23): the engine's payloads as ROS 2 messages
// (poses, sizes, clouds, stamps), learning commands from DDS through the same validation as every
// other command, the relay's bookkeeping (routing, queue full, timeouts), the configuration and the
// ROS 2 names (topics with rmw_cyclonedds' "rt" prefix, type names pkg::msg::dds_::Name_).
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <cstring>
#include <fstream>
#include <limits>
#include <memory>
#include <string>
#include <vector>

#include <Eigen/Geometry>

#include "bridge/bridge_config.hpp"
#include "bridge/command_relay.hpp"
#include "bridge/ros_messages.hpp"
#include "kernels/point_cloud.hpp"

namespace orthoflow::bridge {
namespace {

using Eigen::Vector3d;
constexpr float NaN = std::numeric_limits<float>::quiet_NaN();

std::unique_ptr<engine::ObjectListPayload> list_with(std::uint32_t count) {
  auto list = std::make_unique<engine::ObjectListPayload>();
  std::memset(static_cast<void*>(list.get()), 0, sizeof *list);
  list->reset_header();
  list->count = count;
  list->frame_id = 42;
  list->host_stamp_ns = 5'000'000'123;
  list->age_ns = 7'000'000;
  return list;
}

// An object whose frame is object_from_camera of a pose rotated @p yaw about the camera's y and
// centred at @p centre (camera frame).
void set_object(engine::ObjectEntry& e, std::uint64_t track, const char* label, double yaw,
                const Vector3d& centre) {
  e.track_id = track;
  e.label.assign(label);
  e.score = 0.25F;
  e.unknown = label[0] == '\0' ? 1U : 0U;
  Eigen::Isometry3d camera_from_object = Eigen::Isometry3d::Identity();
  camera_from_object.linear() = Eigen::AngleAxisd(yaw, Vector3d::UnitY()).toRotationMatrix();
  camera_from_object.translation() = centre;
  const Eigen::Matrix4d m = camera_from_object.inverse().matrix();
  for (int r = 0; r < 4; ++r)
    for (int c = 0; c < 4; ++c) e.frame[4 * r + c] = static_cast<float>(m(r, c));
  for (int k = 0; k < 3; ++k) e.centroid[k] = static_cast<float>(centre[k]);
  e.bbox[0] = 0.07F;
  e.bbox[1] = 0.08F;
  e.bbox[2] = 0.20F;
  e.point_count = 900;
  e.flags = engine::OBJECT_DESCRIBED | engine::OBJECT_TAUGHT;
}

TEST(DdsMessages, AnObjectListBecomesAnObjectArrayWithEachObjectsPoseInTheCameraFrame) {
  auto list = list_with(2);
  set_object(list->objects[0], 7, "mug", 0.6, Vector3d(0.1, -0.2, 1.1));
  set_object(list->objects[1], 9, "", -1.2, Vector3d(-0.3, 0.05, 0.9));
  RosScratch scratch;
  RosObjectArray msg{};
  const StampClock clock(1'000'000'000'000);
  ASSERT_EQ(to_ros(*list, clock, scratch, msg), 2U);
  EXPECT_STREQ(msg.header.frame_id, "camera_depth_optical_frame");
  EXPECT_EQ(from_ros_time(msg.header.stamp), 1'005'000'000'123);
  EXPECT_EQ(msg.frame_number, 42U);
  EXPECT_EQ(msg.age_ns, 7'000'000);
  ASSERT_EQ(msg.objects._length, 2U);
  const RosObject& mug = msg.objects._buffer[0];
  EXPECT_EQ(mug.track_id, 7U);
  EXPECT_STREQ(mug.label, "mug");
  EXPECT_FALSE(mug.unknown);
  EXPECT_FLOAT_EQ(mug.score, 0.25F);
  EXPECT_NEAR(mug.pose.position.x, 0.1, 1e-6);
  EXPECT_NEAR(mug.pose.position.y, -0.2, 1e-6);
  EXPECT_NEAR(mug.pose.position.z, 1.1, 1e-6);
  const Eigen::Quaterniond q(mug.pose.orientation.w, mug.pose.orientation.x, mug.pose.orientation.y,
                             mug.pose.orientation.z);
  EXPECT_NEAR(q.norm(), 1.0, 1e-9);
  EXPECT_NEAR(q.angularDistance(Eigen::Quaterniond(Eigen::AngleAxisd(0.6, Vector3d::UnitY()))), 0.0,
              1e-6);
  EXPECT_NEAR(mug.size.y, 0.08, 1e-7);
  EXPECT_EQ(mug.point_count, 900U);
  EXPECT_EQ(mug.flags, engine::OBJECT_DESCRIBED | engine::OBJECT_TAUGHT);
  EXPECT_STREQ(msg.objects._buffer[1].label, "");
  EXPECT_TRUE(msg.objects._buffer[1].unknown);
  EXPECT_FALSE(msg.objects._release) << "the scratch owns the buffer, not Cyclone";
}

TEST(DdsMessages, ABadPoseIsNeverSentAsAPose) {
  auto list = list_with(3);
  set_object(list->objects[0], 1, "a", 0.0, Vector3d(0, 0, 1));
  list->objects[0].frame[5] = NaN;  // not finite
  set_object(list->objects[1], 2, "b", 0.0, Vector3d(0, 0, 1));
  list->objects[1].frame[0] = 2.0F;  // not a rotation
  set_object(list->objects[2], 3, "c", 0.0, Vector3d(0, 0, 1));
  list->objects[2].bbox[1] = std::numeric_limits<float>::infinity();
  RosScratch scratch;
  RosObjectArray msg{};
  ASSERT_EQ(to_ros(*list, StampClock(0), scratch, msg), 3U);
  for (std::uint32_t i = 0; i < 3; ++i) {
    const RosObject& o = msg.objects._buffer[i];
    EXPECT_EQ(o.flags & engine::OBJECT_DESCRIBED, 0U) << i;
    EXPECT_EQ(o.pose.orientation.w, 1.0) << i;
    EXPECT_EQ(o.pose.position.z, 0.0) << i;
    EXPECT_EQ(o.size.x, 0.0) << i;
    EXPECT_NEAR(o.centroid.z, 1.0, 1e-6) << "the centroid stays: " << i;
  }
  // A count beyond the capacity is clamped, never read past the array.
  auto many = list_with(1000);
  EXPECT_EQ(to_ros(*many, StampClock(0), scratch, msg), engine::OBJECT_LIST_CAPACITY);
  auto none = list_with(0);
  EXPECT_EQ(to_ros(*none, StampClock(0), scratch, msg), 0U);
  EXPECT_EQ(msg.objects._length, 0U);
}

TEST(DdsMessages, TheTableVerdictAndWhereUpCameFromTravelWithTheObjects) {
  auto list = list_with(0);
  RosScratch scratch;
  RosObjectArray msg{};
  (void)to_ros(*list, StampClock(0), scratch, msg);  // reset_header(): nothing reported
  EXPECT_FALSE(msg.table);
  EXPECT_STREQ(msg.table_reason, "");
  EXPECT_STREQ(msg.gravity, "");
  const std::array<const char*, 6> reasons{"accepted",  "held",         "no_plane",
                                           "not_level", "out_of_range", "too_small"};
  for (std::uint8_t code = 1; code <= 6; ++code) {
    list->table_reason = code;
    list->gravity = static_cast<std::uint8_t>(1 + code % 3);
    (void)to_ros(*list, StampClock(0), scratch, msg);
    EXPECT_STREQ(msg.table_reason, reasons[code - 1U]);
    EXPECT_EQ(msg.table, code <= 2) << "accepted and held are tables";
    const std::array<const char*, 3> gravities{"none", "sensor", "configured"};
    EXPECT_STREQ(msg.gravity, gravities[code % 3]);
  }
  list->table_reason = 7;  // a code from a newer sender: not reported, never read out of range
  list->gravity = 200;
  (void)to_ros(*list, StampClock(0), scratch, msg);
  EXPECT_FALSE(msg.table);
  EXPECT_STREQ(msg.table_reason, "");
  EXPECT_STREQ(msg.gravity, "");
}

TEST(DdsMessages, AFrameBecomesAnOrganizedPointCloud2AsRosDriversPublishIt) {
  constexpr std::uint32_t W = 5, H = 3;
  std::vector<std::byte> storage(engine::frame_payload_bytes(W, H, engine::FRAME_FIELD_RGB) + 64);
  auto* aligned = reinterpret_cast<std::byte*>(
      (reinterpret_cast<std::uintptr_t>(storage.data()) + 63) & ~std::uintptr_t{63});
  auto span = engine::layout_frame({aligned, storage.size() - 64}, W, H, engine::FRAME_FIELD_RGB);
  ASSERT_TRUE(span);
  span->header->host_stamp_ns = 3'000'000'000;
  for (std::size_t i = 0; i < W * H; ++i) {
    span->points.x[i] = 0.01F * static_cast<float>(i);
    span->points.y[i] = -0.5F;
    span->points.z[i] = i == 7 ? NaN : 1.0F;
    span->rgb[i] = 0xFF102030U + static_cast<std::uint32_t>(i);
  }
  auto view = engine::view_frame({aligned, span->header->payload_bytes});
  ASSERT_TRUE(view) << view.error().to_string();
  RosScratch scratch;
  RosPointCloud2 msg{};
  EXPECT_EQ(to_ros(*view, StampClock(0), scratch, msg), W * H * 16U);
  EXPECT_EQ(msg.width, W);
  EXPECT_EQ(msg.height, H);
  EXPECT_EQ(msg.point_step, 16U);
  EXPECT_EQ(msg.row_step, 16U * W);
  EXPECT_FALSE(msg.is_bigendian);
  EXPECT_FALSE(msg.is_dense) << "one point is NaN";
  ASSERT_EQ(msg.fields._length, 4U);
  const char* names[] = {"x", "y", "z", "rgb"};
  for (std::uint32_t f = 0; f < 4; ++f) {
    EXPECT_STREQ(msg.fields._buffer[f].name, names[f]);
    EXPECT_EQ(msg.fields._buffer[f].offset, 4 * f);
    EXPECT_EQ(msg.fields._buffer[f].datatype, static_cast<std::uint8_t>(PointFieldType::FLOAT32));
    EXPECT_EQ(msg.fields._buffer[f].count, 1U);
  }
  ASSERT_EQ(msg.data._length, W * H * 16U);
  float x = 0.0F;
  std::uint32_t rgb = 0;
  std::memcpy(&x, msg.data._buffer + 6 * 16, 4);
  std::memcpy(&rgb, msg.data._buffer + 6 * 16 + 12, 4);
  EXPECT_FLOAT_EQ(x, 0.06F);
  EXPECT_EQ(rgb, 0x00102036U) << "0x00RRGGBB: alpha is not sent";
  float z = 0.0F;
  std::memcpy(&z, msg.data._buffer + 7 * 16 + 8, 4);
  EXPECT_TRUE(std::isnan(z));
  EXPECT_EQ(from_ros_time(msg.header.stamp), 3'000'000'000);
}

TEST(DdsMessages, RosTimeSplitsLikeRos) {
  builtin_interfaces_msg_dds__Time_ t{};
  to_ros_time(-1, t);
  EXPECT_EQ(t.sec, -1);
  EXPECT_EQ(t.nanosec, 999'999'999U);
  EXPECT_EQ(from_ros_time(t), -1);
  to_ros_time(1'700'000'000'123'456'789, t);
  EXPECT_EQ(t.sec, 1'700'000'000);
  EXPECT_EQ(t.nanosec, 123'456'789U);
}

RosLearningCommand command(std::uint8_t kind, const char* label, std::uint32_t track = 4) {
  RosLearningCommand c{};
  c.client = 99;
  c.request = 5;
  c.kind = kind;
  c.track_id = track;
  c.label = const_cast<char*>(label);
  return c;
}

TEST(DdsMessages, ACommandFromDdsPassesTheSameValidationAsEveryOther) {
  auto ok = from_ros(command(0, "mug"), 1234, 8);
  ASSERT_TRUE(ok) << ok.error().message;
  auto decoded = graphs::decode_command(
      std::as_bytes(std::span<const graphs::LearningCommandPayload, 1>(&*ok, 1)));
  ASSERT_TRUE(decoded);
  EXPECT_EQ(decoded->client, 1234U) << "the bridge's own client id goes to the graph";
  EXPECT_EQ(decoded->request, 8U);
  EXPECT_EQ(decoded->command.kind, graphs::LearningCommand::Kind::TEACH);
  EXPECT_EQ(decoded->command.track_id, 4U);
  EXPECT_EQ(decoded->command.label.view(), "mug");
  EXPECT_TRUE(from_ros(command(3, nullptr), 1, 1)) << "an ask needs no label";
  EXPECT_TRUE(from_ros(command(4, ""), 1, 1)) << "nor an undo";

  const std::string long_label(64, 'a');
  const std::string huge_label(100000, 'b');
  const struct {
    RosLearningCommand c;
    std::uint32_t problem;
  } refused[] = {
      {command(5, "mug"), 255},             // no such kind
      {command(0, ""), 1},                  // EMPTY
      {command(0, nullptr), 1},             // EMPTY
      {command(1, long_label.c_str()), 2},  // TOO_LONG: not cut to 63
      {command(2, huge_label.c_str()), 2},  // TOO_LONG
      {command(0, "caf\xC3"), 3},           // NOT_UTF8
      {command(0, "tab\there"), 4},         // CONTROL_CHARACTER
  };
  for (const auto& r : refused) {
    auto no = from_ros(r.c, 1, 1);
    ASSERT_FALSE(no) << r.problem;
    EXPECT_EQ(no.error().problem, r.problem) << no.error().message;
    EXPECT_FALSE(no.error().message.empty());
  }
  RosLearningCommand anonymous = command(0, "mug");
  anonymous.client = 0;
  EXPECT_FALSE(from_ros(anonymous, 1, 1)) << "acks could not find it";
  RosLearningCommand nowhere = command(0, "mug");
  nowhere.by_position = true;
  nowhere.position.x = std::numeric_limits<double>::infinity();
  auto pos = from_ros(nowhere, 1, 1);
  ASSERT_FALSE(pos);
  EXPECT_EQ(pos.error().problem, 254U);
}

graphs::RemoteAck ack_for(std::uint64_t client, std::uint64_t request) {
  graphs::RemoteAck a;
  a.client = client;
  a.request = request;
  a.status = graphs::AckStatus::ACKNOWLEDGED;
  a.ack.outcome = graphs::LearningAck::Outcome::LEARNED;
  return a;
}

TEST(DdsRelay, AnAckGoesBackToItsSenderAndOtherClientsAcksAreIgnored) {
  CommandRelay relay(1234, 6'000'000'000);
  const RelayDecision a = relay.on_command(command(0, "mug"), 0, true);
  ASSERT_TRUE(a.forward);
  RosLearningCommand second = command(0, "bowl");
  second.client = 77;
  second.request = 1;
  const RelayDecision b = relay.on_command(second, 0, true);
  ASSERT_TRUE(b.forward);
  EXPECT_NE(a.bridge_request, b.bridge_request);
  EXPECT_EQ(relay.pending(), 2U);
  EXPECT_FALSE(relay.on_ack(ack_for(999, a.bridge_request))) << "another iceoryx client's";
  const auto route = relay.on_ack(ack_for(1234, b.bridge_request));
  ASSERT_TRUE(route);
  EXPECT_EQ(route->client, 77U);
  EXPECT_EQ(route->request, 1U);
  EXPECT_FALSE(relay.on_ack(ack_for(1234, b.bridge_request))) << "answered once";
  EXPECT_EQ(relay.pending(), 1U);
  // The first one is never answered: it times out, once.
  EXPECT_FALSE(relay.next_expired(5'000'000'000));
  const auto expired = relay.next_expired(6'000'000'001);
  ASSERT_TRUE(expired);
  EXPECT_EQ(expired->client, 99U);
  EXPECT_EQ(expired->request, 5U);
  EXPECT_FALSE(relay.next_expired(9'000'000'000));
  EXPECT_EQ(relay.pending(), 0U);
}

TEST(DdsRelay, RefusedNoGraphAndAFullQueueAreAnsweredAtOnce) {
  CommandRelay relay(1, 6'000'000'000);
  const RelayDecision bad = relay.on_command(command(0, ""), 0, true);
  EXPECT_FALSE(bad.forward);
  EXPECT_EQ(bad.answer.status, graphs::AckStatus::INVALID);
  EXPECT_EQ(bad.answer.client, 99U);
  EXPECT_EQ(bad.route.request, 5U);
  const RelayDecision nobody = relay.on_command(command(0, "mug"), 0, false);
  EXPECT_FALSE(nobody.forward);
  EXPECT_EQ(nobody.answer.status, graphs::AckStatus::TIMEOUT);
  for (std::size_t i = 0; i < CommandRelay::MAX_PENDING; ++i)
    ASSERT_TRUE(relay.on_command(command(0, "mug"), 0, true).forward) << i;
  const RelayDecision full = relay.on_command(command(0, "mug"), 0, true);
  EXPECT_FALSE(full.forward);
  EXPECT_EQ(full.answer.status, graphs::AckStatus::QUEUE_FULL);
  EXPECT_EQ(relay.pending(), CommandRelay::MAX_PENDING);
}

TEST(DdsConfig, NamesFollowRos2AndRmwCycloneDds) {
  BridgeConfig c;
  const BridgeTopics t = bridge_topics(c);
  EXPECT_EQ(t.objects, "rt/orthoflow/tabletop/objects");
  EXPECT_EQ(t.points, "rt/orthoflow/tabletop/points");
  EXPECT_EQ(t.learning_commands, "rt/orthoflow/tabletop/learning_commands");
  EXPECT_EQ(t.learning_acks, "rt/orthoflow/tabletop/learning_acks");
  // The DDS type names rmw_cyclonedds gives these ROS 2 types (docs/notes/ros2_dds_wire.md b).
  EXPECT_STREQ(sensor_msgs_msg_dds__PointCloud2__desc.m_typename,
               "sensor_msgs::msg::dds_::PointCloud2_");
  EXPECT_STREQ(sensor_msgs_msg_dds__PointField__desc.m_typename,
               "sensor_msgs::msg::dds_::PointField_");
  EXPECT_STREQ(std_msgs_msg_dds__Header__desc.m_typename, "std_msgs::msg::dds_::Header_");
  EXPECT_STREQ(orthoflow_msgs_msg_dds__ObjectArray__desc.m_typename,
               "orthoflow_msgs::msg::dds_::ObjectArray_");
  EXPECT_STREQ(orthoflow_msgs_msg_dds__LearningCommand__desc.m_typename,
               "orthoflow_msgs::msg::dds_::LearningCommand_");
  EXPECT_EQ(orthoflow_msgs_msg_dds__LearningCommand__desc.m_nkeys, 0U) << "keyless, as rmw's";
}

TEST(DdsConfig, LoopbackByDefaultAndAnyOtherNetworkOnlyOnPurpose) {
  BridgeConfig c;
  EXPECT_TRUE(check_bridge_config(c));
  const std::string xml = cyclone_xml(c);
  EXPECT_NE(xml.find("<NetworkInterface name=\"lo\"/>"), std::string::npos) << xml;
  EXPECT_NE(xml.find("<Peer Address=\"127.0.0.1\"/>"), std::string::npos) << xml;
  EXPECT_NE(xml.find("<AllowMulticast>false</AllowMulticast>"), std::string::npos) << xml;
  c.interface = "eth0";
  auto refused = check_bridge_config(c);
  ASSERT_FALSE(refused);
  EXPECT_NE(refused.error().find("--allow-network"), std::string::npos) << refused.error();
  c.allow_network = true;
  EXPECT_TRUE(check_bridge_config(c));
  EXPECT_EQ(cyclone_xml(c).find("AllowMulticast"), std::string::npos) << "multicast discovery";
  c.interface = "10.0.0.1";
  c.peers = {"10.0.0.2"};
  const std::string peers = cyclone_xml(c);
  EXPECT_NE(peers.find("<NetworkInterface address=\"10.0.0.1\"/>"), std::string::npos) << peers;
  EXPECT_NE(peers.find("<Peer Address=\"10.0.0.2\"/>"), std::string::npos) << peers;
  for (const char* bad : {"a b", "x\"/><Evil", ""}) {
    BridgeConfig b;
    b.interface = bad;
    EXPECT_FALSE(check_bridge_config(b)) << bad;
  }
  BridgeConfig g;
  g.graph = "has/slash";
  EXPECT_FALSE(check_bridge_config(g));
}

TEST(DdsConfig, AYamlFileIsReadKeyByKeyAndAnyMistakeIsNamed) {
  const std::string path = ::testing::TempDir() + "bridge.yaml";
  {
    std::ofstream f(path);
    f << "graph: kitchen\ndomain: 7\nframes: true\nmax_frame_hz: 5\n"
         "qos:\n  frames: {reliability: reliable, depth: 2}\n  objects: {durability: "
         "transient_local}\n";
  }
  auto c = load_bridge_config(path);
  ASSERT_TRUE(c) << c.error();
  EXPECT_EQ(c->graph, "kitchen");
  EXPECT_EQ(c->domain, 7U);
  EXPECT_TRUE(c->frames);
  EXPECT_TRUE(c->frames_qos.reliable);
  EXPECT_EQ(c->frames_qos.depth, 2U);
  EXPECT_TRUE(c->objects_qos.transient_local);
  const struct {
    const char* text;
    const char* names;
  } bad[] = {{"domian: 3\n", "domian"},
             {"domain: 300\n", "domain"},
             {"qos:\n  frames: {reliability: sometimes}\n", "qos.frames.reliability"},
             {"qos:\n  video: {depth: 1}\n", "qos.video"},
             {"interface: eth0\n", "--allow-network"},
             {"frames: [1, 2\n", "bridge.yaml"}};
  for (const auto& b : bad) {
    {
      std::ofstream f(path);
      f << b.text;
    }
    auto no = load_bridge_config(path);
    ASSERT_FALSE(no) << b.text;
    EXPECT_NE(no.error().find(b.names), std::string::npos) << no.error();
  }
}

}  // namespace
}  // namespace orthoflow::bridge
