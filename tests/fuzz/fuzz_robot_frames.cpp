// Fuzzes the manipulation folder's text parsers (manipulation/robot_frames.hpp): the first byte
// picks the parser (robot frames YAML, a calibration samples line, a poses line of `orthoflow
// calibrate find-target`, a line of `orthoflow run --json-out`), the rest is its input. No input
// may crash or hit UB; robot frames that parse are a rigid transform that survives format and parse
// again; a samples line that parses holds finite, rigid poses.
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <string_view>

#include "manipulation/robot_frames.hpp"

namespace m = orthoflow::manipulation;

namespace {

bool rigid(const Eigen::Isometry3d& t) {
  const Eigen::Matrix3d r = t.linear();
  return t.matrix().allFinite() &&
         (r.transpose() * r - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff() < 1e-6 &&
         r.determinant() > 0.0;
}

void check(bool ok) {
  if (!ok) std::abort();
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size == 0) return 0;
  const std::string_view text(reinterpret_cast<const char*>(data + 1), size - 1);
  switch (data[0] % 4) {
    case 0: {
      const auto frames = m::parse_robot_frames(text);
      if (frames.has_value()) {
        check(rigid(frames.value().base_from_camera));
        const auto again =
            m::parse_robot_frames(m::format_robot_frames(frames.value(), text.substr(0, 64)));
        check(again.has_value());
        check((again.value().base_from_camera.matrix() - frames.value().base_from_camera.matrix())
                  .cwiseAbs()
                  .maxCoeff() < 1e-9);
      }
      break;
    }
    case 1: {
      const auto line = m::parse_calibration_line(text, orthoflow::drivers::jaco::jaco2_geometry());
      if (line.has_value() && line.value()) {
        if (const auto* p = std::get_if<m::PoseSample>(&line.value()->sample)) {
          check(rigid(p->base_from_gripper) && rigid(p->camera_from_target));
        } else {
          const auto& q = std::get<m::PointSample>(line.value()->sample);
          check(rigid(q.base_from_gripper) && q.target_in_camera.allFinite());
        }
      }
      break;
    }
    case 2: {
      const auto line = m::parse_target_frame_line(text);
      if (line.has_value() && line.value()) {
        check(!line.value()->frame.empty());
        for (const double q : line.value()->joints) check(std::isfinite(q));
      }
      break;
    }
    default: {
      const auto frame = m::parse_run_line(text);
      if (frame.has_value() && frame.value().has_plane) {
        check(frame.value().plane_normal.allFinite() && std::isfinite(frame.value().plane_d));
      }
      break;
    }
  }
  return 0;
}
