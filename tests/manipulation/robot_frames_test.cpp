// The robot frames file, the calibration samples lines and the run's JSON lines
// (manipulation/robot_frames.hpp): round trips, and a clear error for each malformed input.
#include "manipulation/robot_frames.hpp"

#include <fstream>
#include <numbers>

#include <gtest/gtest.h>

namespace orthoflow::manipulation {
namespace {

const drivers::jaco::ArmGeometry& jaco2() { return drivers::jaco::jaco2_geometry(); }

TEST(RobotFrames, FormatAndParseRoundTrip) {
  RobotFrames frames;
  frames.base_from_camera.linear() =
      Eigen::AngleAxisd(2.0, Eigen::Vector3d(0.2, -0.5, 0.8).normalized()).toRotationMatrix();
  frames.base_from_camera.translation() = Eigen::Vector3d(0.25, -1.0, 0.7);
  const std::string text = format_robot_frames(frames, "two\nlines");
  EXPECT_EQ(text.rfind("# two\n# lines\n", 0), 0U);
  const auto parsed = parse_robot_frames(text);
  ASSERT_TRUE(parsed.has_value()) << parsed.error();
  EXPECT_LT((parsed.value().base_from_camera.matrix() - frames.base_from_camera.matrix())
                .cwiseAbs()
                .maxCoeff(),
            1e-12);
}

TEST(RobotFrames, TheShippedSyntheticFramesLoad) {
  const auto frames = load_robot_frames(ORTHOFLOW_SOURCE_DIR "/config/robot_frames_synthetic.yaml");
  ASSERT_TRUE(frames.has_value()) << frames.error();
  // The camera 0.71 m above the table, looking 45 degrees down: its optical axis (z) points down.
  EXPECT_NEAR(frames.value().base_from_camera.translation().z(), 0.7071, 1e-4);
  EXPECT_NEAR(frames.value().base_from_camera.linear().col(2).z(), -std::sqrt(0.5), 1e-9);
}

TEST(RobotFrames, MalformedFramesGetAClearError) {
  const std::pair<const char*, const char*> cases[] = {
      {"[1, 2", "not YAML"},
      {"other: 1", "expected a map with base_from_camera"},
      {"base_from_camera: {translation_m: [0, 0], rotation_wxyz: [1, 0, 0, 0]}",
       "translation_m: expected a list of 3"},
      {"base_from_camera: {translation_m: [0, 0, x], rotation_wxyz: [1, 0, 0, 0]}",
       "'x' is not a finite number"},
      {"base_from_camera: {translation_m: [0, 0, .nan], rotation_wxyz: [1, 0, 0, 0]}",
       "not a finite number"},
      {"base_from_camera: {translation_m: [0, 0, 0], rotation_wxyz: [1, 1, 0, 0]}",
       "not a unit quaternion"},
      {"base_from_camera: {translation_m: [0, 0, 0]}", "rotation_wxyz: expected a list of 4"},
      {"base_from_camera: {translation_m: [0, 0, 0], translation_m: [1, 0, 0], rotation_wxyz: "
       "[1, 0, 0, 0]}",
       "key 'translation_m' appears twice in one map"},
  };
  for (const auto& [text, message] : cases) {
    const auto parsed = parse_robot_frames(text);
    ASSERT_FALSE(parsed.has_value()) << text;
    EXPECT_NE(parsed.error().find(message), std::string::npos) << text << " -> " << parsed.error();
  }
  EXPECT_NE(load_robot_frames("/nonexistent/frames.yaml").error().find("cannot open"),
            std::string::npos);
}

TEST(CalibrationLine, JointsAndTargetPose) {
  const auto line = parse_calibration_line(
      R"({"joints": [275, 167.5, 57.5, 240, 82.5, 75], "target": {"position": [0.1, 0.2, 0.9], "theta": [0.1, -0.2, 0.3]}})",
      jaco2());
  ASSERT_TRUE(line.has_value()) << line.error();
  ASSERT_TRUE(line.value().has_value());
  const auto& s = std::get<PoseSample>(line.value()->sample);
  EXPECT_TRUE(s.base_from_gripper.isApprox(
      drivers::jaco::forward_kinematics({275, 167.5, 57.5, 240, 82.5, 75})));
  EXPECT_TRUE(s.camera_from_target.isApprox(
      drivers::jaco::to_transform({{0.1, 0.2, 0.9}, {0.1, -0.2, 0.3}})));
}

TEST(CalibrationLine, CartesianGripperAndTargetPoint) {
  const auto line = parse_calibration_line(
      R"({"gripper": {"position": [0.2, -0.3, 0.4], "theta": [3.1, 0, 1.5]}, "target_point": [0.1, 0.2, 0.9]})",
      jaco2());
  ASSERT_TRUE(line.has_value()) << line.error();
  const auto& s = std::get<PointSample>(line.value()->sample);
  EXPECT_TRUE(s.target_in_camera.isApprox(Eigen::Vector3d(0.1, 0.2, 0.9)));
  EXPECT_TRUE(s.base_from_gripper.translation().isApprox(Eigen::Vector3d(0.2, -0.3, 0.4)));
}

TEST(CalibrationLine, BlankAndCommentLinesAreSkipped) {
  for (const char* text : {"", "   ", "# a comment", "  # indented"}) {
    const auto line = parse_calibration_line(text, jaco2());
    ASSERT_TRUE(line.has_value());
    EXPECT_FALSE(line.value().has_value()) << text;
  }
}

TEST(CalibrationLine, MalformedLinesGetAClearError) {
  const std::pair<const char*, const char*> cases[] = {
      {"{", "not a JSON object"},
      {"[1]", "not a JSON object"},
      {R"({"target_point": [0, 0, 1]})", "exactly one of \"joints\" and \"gripper\""},
      {R"({"joints": [1, 2, 3], "target_point": [0, 0, 1]})", "6 actuator angles"},
      {R"({"joints": [1, 2, 3, 4, 5, "x"], "target_point": [0, 0, 1]})",
       "element 5 is not a finite number"},
      {R"({"joints": [1, 2, 3, 4, 5, 6]})", "exactly one of \"target\" and \"target_point\""},
      {R"({"joints": [1, 2, 3, 4, 5, 6], "target_point": [0, 1]})",
       "target_point: expected [x, y, z]"},
      {R"({"joints": [1, 2, 3, 4, 5, 6], "target": {"position": [0, 0, 1]}})", "target: expected"},
      {R"({"gripper": {"position": [0, 0, 1], "theta": [0, "x", 0]}, "target_point": [0, 0, 1]})",
       "gripper.theta: element 1 is not a finite number"},
  };
  for (const auto& [text, message] : cases) {
    const auto line = parse_calibration_line(text, jaco2());
    ASSERT_FALSE(line.has_value()) << text;
    EXPECT_NE(line.error().find(message), std::string::npos) << text << " -> " << line.error();
  }
  EXPECT_FALSE(parse_calibration_line(std::string(5000, ' ') + "{}", jaco2()).has_value());
}

TEST(RunLine, ObjectsFramesAndThePlane) {
  const auto frame = parse_run_line(
      R"({"frame":7,"plane":{"normal":[0,-0.7,-0.7],"d":0.7},"objects":[{"track":3,"label":"mug","truth":"mug",)"
      R"("bbox":[0.1,0.1,0.1],"frame":[1,0,0,0,0,1,0,0,0,0,1,0,0,0,0,1]},{"track":4,"label":null}]})");
  ASSERT_TRUE(frame.has_value()) << frame.error();
  EXPECT_EQ(frame.value().frame, 7U);
  EXPECT_TRUE(frame.value().has_plane);
  ASSERT_EQ(frame.value().objects.size(), 2U);
  EXPECT_EQ(frame.value().objects[0].label, "mug");
  EXPECT_TRUE(frame.value().objects[0].described);
  EXPECT_FALSE(frame.value().objects[1].described);
  EXPECT_TRUE(frame.value().objects[1].label.empty());
}

TEST(RunLine, MalformedLinesGetAClearError) {
  EXPECT_NE(parse_run_line("{").error().find("not a JSON object"), std::string::npos);
  EXPECT_NE(parse_run_line(R"({"objects": 3})").error().find("objects: not a list"),
            std::string::npos);
  EXPECT_NE(parse_run_line(R"({"objects": [{"frame": [1], "bbox": [1, 2, 3]}]})")
                .error()
                .find("16 numbers"),
            std::string::npos);
  EXPECT_NE(parse_run_line(R"({"plane": {"normal": [0, 1], "d": 1}})").error().find("plane.normal"),
            std::string::npos);
}

}  // namespace
}  // namespace orthoflow::manipulation
