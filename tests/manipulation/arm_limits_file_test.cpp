// The arm's limits file (manipulation/arm_limits_file.hpp): the default keep-outs, a file's keys,
// and every refusal naming its key (docs/SAFETY.md).
#include "manipulation/arm_limits_file.hpp"

#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>

namespace orthoflow::manipulation {
namespace {

namespace jaco = drivers::jaco;

std::string refusal(std::string_view yaml) {
  auto r = parse_arm_limits(yaml, "limits.yaml");
  EXPECT_FALSE(r) << yaml;
  return r ? std::string() : r.error();
}

TEST(ArmLimitsFile, DefaultsKeepTheTableAndTheBaseOut) {
  const ArmLimitsFile f = default_arm_limits();
  const jaco::Box* table = f.limits.find_keep_out("table");
  ASSERT_NE(table, nullptr);
  EXPECT_DOUBLE_EQ(table->max.z(), 0.0);
  EXPECT_EQ(table->from, jaco::BodyPart::UPPER_ARM);
  const jaco::Box* base = f.limits.find_keep_out("base");
  ASSERT_NE(base, nullptr);
  EXPECT_EQ(base->from, jaco::BodyPart::FOREARM);
  EXPECT_EQ(f.limits.find_keep_out("camera"), nullptr);  // placed once robot frames are known
  // An empty file is the defaults.
  auto empty = parse_arm_limits("", "empty.yaml");
  ASSERT_TRUE(empty) << empty.error();
  EXPECT_EQ(empty->limits.keep_out_count, f.limits.keep_out_count);
}

TEST(ArmLimitsFile, AFileSetsHeightsRatesAndBoxes) {
  auto f = parse_arm_limits(R"(
table_height_m: -0.02
workspace_m: [-0.8, -0.8, -0.1, 0.8, 0.8, 1.1]
keep_out:
  - {name: shelf, box_m: [0.3, 0.3, 0.0, 0.6, 0.6, 0.4], from: hand}
speed_deg_s: 20
accel_deg_s2: 30
brake_decel_deg_s2: 35
command_latency_ms: 30
camera_half_extent_m: [0.2, 0.1, 0.1]
camera_mount: false
)",
                            "robot.yaml");
  ASSERT_TRUE(f) << f.error();
  EXPECT_DOUBLE_EQ(f->table_height_m, -0.02);
  EXPECT_DOUBLE_EQ(f->limits.find_keep_out("table")->max.z(), -0.02);
  EXPECT_DOUBLE_EQ(f->limits.workspace.max.x(), 0.8);
  const jaco::Box* shelf = f->limits.find_keep_out("shelf");
  ASSERT_NE(shelf, nullptr);
  EXPECT_EQ(shelf->from, jaco::BodyPart::HAND);
  EXPECT_DOUBLE_EQ(f->limits.max_joint_speed_deg_s, 20.0);
  EXPECT_DOUBLE_EQ(f->limits.max_joint_accel_deg_s2, 30.0);
  EXPECT_DOUBLE_EQ(f->limits.brake_decel_deg_s2, 35.0);
  EXPECT_EQ(f->limits.command_latency_ns, 30'000'000);
  EXPECT_FALSE(f->camera_mount);
  EXPECT_EQ(f->source, "robot.yaml");
}

TEST(ArmLimitsFile, OnlyAPersonSayingSoRemovesADefault) {
  auto f = parse_arm_limits("remove: [table, camera]\n", "f.yaml");
  ASSERT_TRUE(f) << f.error();
  EXPECT_EQ(f->limits.find_keep_out("table"), nullptr);
  EXPECT_NE(f->limits.find_keep_out("base"), nullptr);
  EXPECT_TRUE(f->camera_removed);
  ASSERT_TRUE(place_camera_keep_out(*f, Eigen::Isometry3d::Identity()));
  EXPECT_EQ(f->limits.find_keep_out("camera"), nullptr);
  EXPECT_NE(describe_limits(*f).find("removed by the file: table camera"), std::string::npos);
}

TEST(ArmLimitsFile, TheCameraAndItsMountArePlacedFromTheRobotFrames) {
  ArmLimitsFile f = default_arm_limits();
  Eigen::Isometry3d base_from_camera = Eigen::Isometry3d::Identity();
  base_from_camera.translation() = Eigen::Vector3d(0.2, -0.5, 0.56);
  base_from_camera.linear() =
      Eigen::AngleAxisd(0.5 * M_PI, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  ASSERT_TRUE(place_camera_keep_out(f, base_from_camera));
  const jaco::Box* camera = f.limits.find_keep_out("camera");
  ASSERT_NE(camera, nullptr);
  // Turned a quarter about z: the camera's x half-extent (0.15) lies along the base's y.
  EXPECT_NEAR(camera->min.y(), -0.65, 1e-9);
  EXPECT_NEAR(camera->max.x(), 0.30, 1e-9);
  const jaco::Box* mount = f.limits.find_keep_out("camera_mount");
  ASSERT_NE(mount, nullptr);
  EXPECT_NEAR(mount->min.z(), 0.0, 1e-12);
  EXPECT_NEAR(mount->max.z(), camera->min.z(), 1e-12);
  EXPECT_TRUE(camera->contains(base_from_camera.translation()));
  // Placing twice adds nothing.
  const std::size_t count = f.limits.keep_out_count;
  ASSERT_TRUE(place_camera_keep_out(f, base_from_camera));
  EXPECT_EQ(f.limits.keep_out_count, count);
  base_from_camera.translation().x() = std::nan("");
  ArmLimitsFile g = default_arm_limits();
  EXPECT_FALSE(place_camera_keep_out(g, base_from_camera));
}

TEST(ArmLimitsFile, RefusalsNameTheKey) {
  EXPECT_NE(refusal("speed: 10").find("speed: unknown key"), std::string::npos);
  EXPECT_NE(
      refusal("speed_deg_s: 10\nspeed_deg_s: 20").find("line 2: key 'speed_deg_s' appears twice"),
      std::string::npos);
  EXPECT_NE(refusal("speed_deg_s: 50").find("speed_deg_s"), std::string::npos);  // > 36 deg/s
  EXPECT_NE(refusal("speed_deg_s: .nan").find("not a finite number"), std::string::npos);
  EXPECT_NE(refusal("speed_deg_s: -1").find("speed_deg_s"), std::string::npos);
  EXPECT_NE(refusal("accel_deg_s2: 1e300").find("accel_deg_s2"), std::string::npos);
  EXPECT_NE(refusal("accel_deg_s2: 60").find("brake_decel_deg_s2"), std::string::npos);
  EXPECT_NE(refusal("command_latency_ms: 1").find("command_latency_ms"), std::string::npos);
  EXPECT_NE(refusal("workspace_m: [-2, -0.9, -0.1, 0.9, 0.9, 1.2]").find("reach"),
            std::string::npos);
  EXPECT_NE(refusal("workspace_m: [0.9, -0.9, -0.1, -0.9, 0.9, 1.2]").find("inverted"),
            std::string::npos);
  EXPECT_NE(refusal("keep_out: [{name: a, box_m: [0, 0, 0, 0, 1, 1]}]").find("keep_out.a.box_m"),
            std::string::npos);  // degenerate: zero width
  EXPECT_NE(refusal("keep_out: [{name: a, box_m: [0, 0, 0, 1, 1]}]").find("keep_out.a.box_m"),
            std::string::npos);
  EXPECT_NE(refusal("keep_out: [{name: a, box_m: [0, 0, 0, 1, 1, 1], colour: red}]")
                .find("keep_out.colour: unknown key"),
            std::string::npos);
  EXPECT_NE(refusal("keep_out: [{name: a, box_m: [0, 0, 0, 1, 1, 1], from: elbow}]")
                .find("keep_out.a.from"),
            std::string::npos);
  EXPECT_NE(refusal("keep_out: [{name: table, box_m: [0, 0, 0, 1, 1, 1]}]").find("two boxes"),
            std::string::npos);
  EXPECT_NE(refusal("remove: [floor]").find("remove"), std::string::npos);
  EXPECT_NE(refusal("table_height_m: 3").find("table_height_m"), std::string::npos);
  EXPECT_NE(refusal("[1, 2]").find("a map"), std::string::npos);
  EXPECT_NE(refusal("{unclosed").find("not YAML"), std::string::npos);
  std::string many = "keep_out:\n";
  for (int i = 0; i < 8; ++i)
    many += "  - {name: b" + std::to_string(i) + ", box_m: [0, 0, 0, 1, 1, 1]}\n";
  EXPECT_NE(refusal(many).find("at most 8"), std::string::npos);
}

TEST(ArmLimitsFile, LoadRefusesWhatIsNotASmallRegularFile) {
  const auto dir =
      std::filesystem::temp_directory_path() / ("orthoflow_limits_" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  EXPECT_NE(load_arm_limits((dir / "missing.yaml").string()).error().find("cannot read"),
            std::string::npos);
  EXPECT_NE(load_arm_limits(dir.string()).error().find("not a regular file"), std::string::npos);
  {
    std::ofstream big(dir / "big.yaml");
    big << "# " << std::string(70 * 1024, 'x') << '\n';
  }
  EXPECT_NE(load_arm_limits((dir / "big.yaml").string()).error().find("64 KiB"), std::string::npos);
  {
    std::ofstream ok(dir / "ok.yaml");
    ok << "table_height_m: 0.01\n";
  }
  auto loaded = load_arm_limits((dir / "ok.yaml").string());
  ASSERT_TRUE(loaded) << loaded.error();
  EXPECT_DOUBLE_EQ(loaded->table_height_m, 0.01);
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace orthoflow::manipulation
