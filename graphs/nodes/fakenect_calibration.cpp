#include "graphs/nodes/fakenect_calibration.hpp"

#include <cmath>
#include <nlohmann/json.hpp>

#include "formats/file_bytes.hpp"

namespace orthoflow::graphs {

namespace {

using formats::IoError;

/// fakenect stores every registration word but these five (the mapping does not use them).
bool stored_by_fakenect(std::string_view name) {
  return name != "dx_center" && name != "rollout_blank" && name != "rollout_size" &&
         name != "back_comp1" && name != "back_comp2";
}

}  // namespace

std::string fakenect_device_json(const drivers::kinect::Calibration& c) {
  nlohmann::ordered_json reg;
  for (std::size_t i = 0; i < c.reg.words.size(); ++i) {
    const char* key = drivers::kinect::reg_info_name(i);
    if (stored_by_fakenect(key)) reg[key] = c.reg.words[i];
  }
  reg["pad_info"] = {{"start_lines", c.pad.start_lines},
                     {"end_lines", c.pad.end_lines},
                     {"cropping_lines", c.pad.cropping_lines}};
  reg["zero_plane_info"] = {{"dcmos_emitter_distance", c.zero_plane.dcmos_emitter_dist_cm},
                            {"dcmos_rcmos_distance", c.zero_plane.dcmos_rcmos_dist_cm},
                            {"reference_distance", c.zero_plane.reference_distance_mm},
                            {"reference_pixel_size", c.zero_plane.reference_pixel_size_mm}};
  nlohmann::ordered_json root;
  root["reg_info"] = reg;
  root["const_shift"] = c.const_shift;
  return root.dump(2) + "\n";
}

Result<void, IoError> write_fakenect_device(const std::filesystem::path& path,
                                            const drivers::kinect::Calibration& calibration) {
  return formats::write_file_atomically(path, fakenect_device_json(calibration));
}

Result<drivers::kinect::Calibration, IoError> parse_fakenect_device(std::string_view text,
                                                                    const std::string& name) {
  const nlohmann::json root = nlohmann::json::parse(text, nullptr, /*allow_exceptions=*/false);
  auto bad = [&](IoError::Code code, const std::string& what) {
    return IoError{code, name + ": " + what};
  };
  if (root.is_discarded() || !root.is_object())
    return err(bad(IoError::Code::BAD_HEADER, "not a JSON object"));
  const nlohmann::json empty = nlohmann::json::object();
  auto member = [&](const nlohmann::json& obj, const char* key) -> const nlohmann::json& {
    return obj.is_object() && obj.contains(key) ? obj[key] : empty;
  };
  double v = 0;
  auto number = [&](const nlohmann::json& obj, const char* key, double lo,
                    double hi) -> Result<void, IoError> {
    const nlohmann::json& n = member(obj, key);
    if (!n.is_number())
      return err(bad(IoError::Code::BAD_HEADER, std::string("missing number '") + key + "'"));
    v = n.get<double>();
    if (!std::isfinite(v) || v < lo || v > hi)
      return err(bad(IoError::Code::BAD_NUMBER, std::string("'") + key + "' out of range"));
    return {};
  };
  const nlohmann::json& reg = member(root, "reg_info");
  if (!reg.is_object()) return err(bad(IoError::Code::BAD_HEADER, "missing object 'reg_info'"));
  drivers::kinect::Calibration c;
  c.reg.words.fill(0);
  for (std::size_t i = 0; i < c.reg.words.size(); ++i) {
    const char* key = drivers::kinect::reg_info_name(i);
    if (!stored_by_fakenect(key)) continue;
    if (auto ok = number(reg, key, -2147483648.0, 2147483647.0); !ok) return err(ok.error());
    c.reg.words[i] = static_cast<std::int32_t>(v);
  }
  const nlohmann::json& pad = member(reg, "pad_info");
  std::uint16_t* pads[] = {&c.pad.start_lines, &c.pad.end_lines, &c.pad.cropping_lines};
  const char* pad_keys[] = {"start_lines", "end_lines", "cropping_lines"};
  for (std::size_t k = 0; k < 3; ++k) {
    if (auto ok = number(pad, pad_keys[k], 0, 1024); !ok) return err(ok.error());
    *pads[k] = static_cast<std::uint16_t>(v);
  }
  const nlohmann::json& zp = member(reg, "zero_plane_info");
  if (auto ok = number(zp, "dcmos_emitter_distance", 1, 20); !ok) return err(ok.error());
  c.zero_plane.dcmos_emitter_dist_cm = static_cast<float>(v);
  if (auto ok = number(zp, "dcmos_rcmos_distance", 0, 20); !ok) return err(ok.error());
  c.zero_plane.dcmos_rcmos_dist_cm = static_cast<float>(v);
  c.reported_rcmos_dist_cm = c.zero_plane.dcmos_rcmos_dist_cm;
  if (auto ok = number(zp, "reference_distance", 50, 500); !ok) return err(ok.error());
  c.zero_plane.reference_distance_mm = static_cast<float>(v);
  if (auto ok = number(zp, "reference_pixel_size", 0.05, 0.2); !ok) return err(ok.error());
  c.zero_plane.reference_pixel_size_mm = static_cast<float>(v);
  if (auto ok = number(root, "const_shift", 1, 2047); !ok) return err(ok.error());
  c.const_shift = static_cast<std::uint16_t>(std::lround(v));
  return c;
}

Result<drivers::kinect::Calibration, IoError> read_fakenect_device(
    const std::filesystem::path& path) {
  auto bytes = formats::read_file_bytes(path, std::size_t{1} << 20);
  if (!bytes) return err(bytes.error());
  return parse_fakenect_device(std::string_view(bytes->data(), bytes->size()), path.string());
}

}  // namespace orthoflow::graphs
