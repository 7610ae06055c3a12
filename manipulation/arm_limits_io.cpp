// The arm's limits file (arm_limits_file.hpp), its other half: reading the file from disk, placing
// the camera's keep-out where the robot frames put the camera, and the limits as text.
#include <sys/stat.h>

#include <array>
#include <cstdio>
#include <fstream>
#include <sstream>

#include "manipulation/arm_limits_file.hpp"

namespace orthoflow::manipulation {
namespace {

namespace jaco = drivers::jaco;

constexpr std::size_t MAX_FILE_BYTES = 64 * 1024;
// The camera's mount: a column this wide (half-width) under the camera, down to the table.
constexpr double MOUNT_HALF_WIDTH_M = 0.04;

std::string vec(const Eigen::Vector3d& v) {
  char text[96];
  std::snprintf(text, sizeof text, "[%.3f, %.3f, %.3f]", v.x(), v.y(), v.z());
  return text;
}

}  // namespace

Result<ArmLimitsFile, std::string> load_arm_limits(const std::string& path) {
  struct stat st {};
  if (::stat(path.c_str(), &st) != 0) return err(path + ": cannot read it (no such file?)");
  if (!S_ISREG(st.st_mode)) return err(path + ": not a regular file");
  if (static_cast<std::size_t>(st.st_size) > MAX_FILE_BYTES)
    return err(path + ": larger than 64 KiB; not a limits file");
  std::ifstream in(path, std::ios::binary);
  if (!in) return err(path + ": cannot open it");
  std::ostringstream text;
  text << in.rdbuf();
  return parse_arm_limits(text.str(), path);
}

Result<void, std::string> place_camera_keep_out(ArmLimitsFile& file,
                                                const Eigen::Isometry3d& base_from_camera) {
  if (file.camera_removed) return {};
  if (file.limits.find_keep_out("camera") != nullptr) return {};
  if (!base_from_camera.matrix().allFinite()) return err("camera: the camera's pose is not finite");
  Eigen::Vector3d lo = Eigen::Vector3d::Constant(1e9);
  Eigen::Vector3d hi = Eigen::Vector3d::Constant(-1e9);
  for (int corner = 0; corner < 8; ++corner) {
    const Eigen::Vector3d sign((corner & 1) != 0 ? 1.0 : -1.0, (corner & 2) != 0 ? 1.0 : -1.0,
                               (corner & 4) != 0 ? 1.0 : -1.0);
    const Eigen::Vector3d p = base_from_camera * sign.cwiseProduct(file.camera_half_extent_m);
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
  }
  if (!lo.allFinite() || !hi.allFinite()) return err("camera: the camera's pose is not finite");
  jaco::Box camera{lo, hi, core::FixedText<24>::from("camera")};
  if (!file.limits.add_keep_out(camera))
    return err("camera: no room for the camera's keep-out (at most " +
               std::to_string(jaco::MAX_KEEP_OUT) + " boxes)");
  const Eigen::Vector3d centre = base_from_camera.translation();
  if (file.camera_mount && lo.z() > file.table_height_m) {
    jaco::Box mount{
        {centre.x() - MOUNT_HALF_WIDTH_M, centre.y() - MOUNT_HALF_WIDTH_M, file.table_height_m},
        {centre.x() + MOUNT_HALF_WIDTH_M, centre.y() + MOUNT_HALF_WIDTH_M, lo.z()},
        core::FixedText<24>::from("camera_mount")};
    if (!file.limits.add_keep_out(mount))
      return err("camera_mount: no room for the mount's keep-out");
  }
  return {};
}

std::string describe_limits(const ArmLimitsFile& file) {
  const jaco::SafetyLimits& l = file.limits;
  std::ostringstream out;
  out << "limits from " << file.source << '\n'
      << "  workspace_m " << vec(l.workspace.min) << " .. " << vec(l.workspace.max) << '\n'
      << "  table_height_m " << file.table_height_m << '\n'
      << "  speed_deg_s " << l.max_joint_speed_deg_s << "  accel_deg_s2 "
      << l.max_joint_accel_deg_s2 << "  brake_decel_deg_s2 " << l.brake_decel_deg_s2
      << "  command_latency_ms " << static_cast<double>(l.command_latency_ns) / 1e6 << '\n'
      << "  keep-outs (" << l.keep_out_count << "):\n";
  for (std::size_t i = 0; i < l.keep_out_count; ++i) {
    const jaco::Box& b = l.keep_out[i];
    out << "    " << b.name.view() << ' ' << vec(b.min) << " .. " << vec(b.max) << "  from "
        << jaco::to_string(b.from) << '\n';
  }
  if (!file.removed.empty()) {
    out << "  removed by the file:";
    for (const std::string& r : file.removed) out << ' ' << r;
    out << '\n';
  }
  if (!file.camera_removed && l.find_keep_out("camera") == nullptr)
    out << "  camera: not placed (no robot frames given; pass --frames to place it)\n";
  return out.str();
}

}  // namespace orthoflow::manipulation
