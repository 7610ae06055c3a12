// `orthoflow info FILE [--json]`: what a .pcd or .ply file holds (fields, size, layout, finite
// points, bounding box, viewpoint, encoding). The file is read whole with the same readers the
// engine uses, so a file `info` accepts is a file the pipeline accepts; any reader error is
// reported as bad input.
#include <array>
#include <charconv>
#include <cstdint>
#include <iostream>
#include <memory>
#include <nlohmann/json.hpp>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "apps/commands.hpp"
#include "apps/json_numbers.hpp"
#include "formats/file_bytes.hpp"
#include "formats/pcd_io.hpp"
#include "formats/ply_header.hpp"
#include "formats/ply_reader.hpp"
#include "kernels/cloud_stats.hpp"

namespace orthoflow::apps {
namespace {

/// What `info` reports besides what the cloud itself says.
struct FileSummary {
  std::string format;    ///< "pcd" or "ply"
  std::string version;   ///< PCD VERSION (empty when absent) or PLY "1.0"
  std::string encoding;  ///< "ascii", "binary", "binary_compressed", "binary_little_endian", ...
  nlohmann::json fields = nlohmann::json::array();
  kernels::PointCloud cloud;
};

/// PCD-style type letter and size, e.g. "F4", "U1" (PLY properties are reported the same way).
std::string type_name(formats::ScalarType type) {
  using formats::ScalarType;
  const char letter =
      type == ScalarType::FLOAT32 || type == ScalarType::FLOAT64                           ? 'F'
      : type == ScalarType::INT8 || type == ScalarType::INT16 || type == ScalarType::INT32 ? 'I'
                                                                                           : 'U';
  return std::string(1, letter) + std::to_string(formats::scalar_size(type));
}

[[noreturn]] void bad_input(const formats::IoError& error) {
  std::cerr << "orthoflow info: " << error.to_string() << '\n';
  throw CLI::RuntimeError(EXIT_BAD_INPUT);
}

FileSummary summarize_pcd(std::span<const char> bytes, const std::string& name) {
  auto header_result = formats::parse_pcd_header(bytes, name);
  if (!header_result) { bad_input(header_result.error()); }
  auto cloud_result = formats::read_pcd_buffer(bytes, name);
  if (!cloud_result) { bad_input(cloud_result.error()); }
  FileSummary s{"pcd",
                header_result->version,
                formats::to_string(header_result->encoding),
                {},
                std::move(*cloud_result)};
  for (const formats::PointField& f : header_result->fields) {
    s.fields.push_back({{"name", f.name}, {"type", type_name(f.type)}, {"count", f.count}});
  }
  return s;
}

FileSummary summarize_ply(std::span<const char> bytes, const std::string& name) {
  auto header_result = formats::parse_ply_header(bytes, name);
  if (!header_result) { bad_input(header_result.error()); }
  auto cloud_result = formats::read_ply_buffer(bytes, name);
  if (!cloud_result) { bad_input(cloud_result.error()); }
  constexpr std::array<const char*, 3> FORMATS{"ascii", "binary_little_endian",
                                               "binary_big_endian"};
  FileSummary s{"ply",
                "1.0",
                FORMATS[static_cast<std::size_t>(header_result->format)],
                {},
                std::move(*cloud_result)};
  for (const formats::PlyElement& e : header_result->elements) {
    if (e.name != "vertex") { continue; }  // faces and other elements are skipped by the reader
    for (const formats::PlyProperty& p : e.properties) {
      s.fields.push_back({{"name", p.name},
                          {"type", (p.is_list ? "list " : "") + type_name(p.type)},
                          {"count", 1}});
    }
  }
  return s;
}

/// JSON numbers cannot be inf; an empty box (no finite point) is reported as null.
nlohmann::json box_json(const kernels::CloudStats& stats) {
  if (stats.finite == 0) { return nullptr; }
  return {{"min", floats_json(stats.min)}, {"max", floats_json(stats.max)}};
}

nlohmann::json summary_json(const std::string& path, const FileSummary& s) {
  const kernels::CloudStats stats = kernels::cloud_stats(s.cloud.points());
  const kernels::Viewpoint& vp = s.cloud.info.viewpoint;
  return {
      {"file", path},
      {"format", s.format},
      {"version", s.version},
      {"encoding", s.encoding},
      {"fields", s.fields},
      {"points", s.cloud.size()},
      {"width", s.cloud.width()},
      {"height", s.cloud.height()},
      {"organized", s.cloud.organized()},
      {"finite_points", stats.finite},
      {"bounding_box", box_json(stats)},
      {"viewpoint",
       {{"origin", floats_json(vp.origin)}, {"orientation_wxyz", floats_json(vp.orientation)}}}};
}

std::string list3(const nlohmann::json& values) {
  std::string out = "[";
  for (std::size_t i = 0; i < values.size(); ++i) { out += (i ? ", " : "") + values[i].dump(); }
  return out + "]";
}

void print_text(const nlohmann::json& j) {
  std::cout << "file:        " << j["file"].get<std::string>() << '\n'
            << "format:      " << j["format"].get<std::string>() << ' '
            << j["version"].get<std::string>() << " (" << j["encoding"].get<std::string>() << ")\n"
            << "fields:     ";
  for (const auto& f : j["fields"]) {
    std::cout << ' ' << f["name"].get<std::string>() << ':' << f["type"].get<std::string>()
              << (f["count"].get<std::uint32_t>() > 1 ? "x" + f["count"].dump() : "");
  }
  std::cout << "\npoints:      " << j["points"] << "\nlayout:      " << j["width"] << " x "
            << j["height"] << (j["organized"].get<bool>() ? " (organized)" : " (unorganized)")
            << "\nfinite:      " << j["finite_points"] << '\n';
  if (j["bounding_box"].is_null()) {
    std::cout << "bbox:        none (no finite point)\n";
  } else {
    std::cout << "bbox:        min " << list3(j["bounding_box"]["min"]) << " max "
              << list3(j["bounding_box"]["max"]) << '\n';
  }
  std::cout << "viewpoint:   origin " << list3(j["viewpoint"]["origin"])
            << " orientation (w x y z) " << list3(j["viewpoint"]["orientation_wxyz"]) << '\n';
}

void run_info(const std::string& path, bool as_json) {
  auto bytes_result = formats::read_file_bytes(path);
  if (!bytes_result) { bad_input(bytes_result.error()); }
  const std::vector<char>& bytes = *bytes_result;
  // Dispatch on content, not extension: every PLY file starts with the magic line "ply".
  const bool is_ply = bytes.size() >= 4 && std::string_view(bytes.data(), 3) == "ply" &&
                      (bytes[3] == '\n' || bytes[3] == '\r');
  const FileSummary summary = is_ply ? summarize_ply(bytes, path) : summarize_pcd(bytes, path);
  const nlohmann::json j = summary_json(path, summary);
  if (as_json) {
    std::cout << j.dump(2) << '\n';
  } else {
    print_text(j);
  }
}

}  // namespace

void add_info_command(CLI::App& app) {
  auto* cmd = app.add_subcommand(
      "info", "Describe a .pcd or .ply file: fields, size, layout, bounding box");
  auto path = std::make_shared<std::string>();
  auto as_json = std::make_shared<bool>(false);
  cmd->add_option("file", *path, "PCD or PLY file")->required();
  cmd->add_flag("--json", *as_json, "print one JSON object instead of text");
  cmd->callback([path, as_json] { run_info(*path, *as_json); });
}

}  // namespace orthoflow::apps
