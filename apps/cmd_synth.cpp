// `orthoflow synth` (one synthetic Kinect tabletop frame + ground truth) and `orthoflow
// synth-dataset` (the object-view corpus). Both are thin wrappers over drivers/synthetic_scene.hpp
// and drivers/object_dataset.hpp.
#include <cmath>
#include <cstdint>
#include <fstream>
#include <iostream>
#include <memory>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <vector>

#include "apps/commands.hpp"
#include "core/file_output.hpp"
#include "formats/pcd_io.hpp"
#include "simulation/world/object_dataset.hpp"
#include "simulation/world/synthetic_scene.hpp"

namespace orthoflow::apps {
namespace {

using simulation::Category;

constexpr double RAD_TO_DEG = 180.0 / 3.14159265358979323846;

/// "mug,plate" -> categories; prints the unknown name and throws EXIT_USAGE.
std::vector<Category> parse_categories(const std::string& list) {
  std::vector<Category> out;
  std::stringstream in(list);
  std::string name;
  while (std::getline(in, name, ',')) {
    if (name.empty()) { continue; }
    const auto maybe_category = simulation::category_from_name(name);
    if (!maybe_category) {
      std::cerr << "unknown category '" << name << "' (known: ";
      for (std::size_t i = 0; i < simulation::CATEGORY_COUNT; ++i) {
        std::cerr << (i ? "," : "") << simulation::category_name(static_cast<Category>(i));
      }
      std::cerr << ")\n";
      throw CLI::RuntimeError(EXIT_USAGE);
    }
    out.push_back(*maybe_category);
  }
  return out;
}

nlohmann::json vec(const simulation::Vec3& v) { return nlohmann::json::array({v[0], v[1], v[2]}); }

nlohmann::json ground_truth(const simulation::Scene& scene, const kernels::PointCloud& cloud,
                            std::uint64_t seed) {
  const simulation::TableFrame f = simulation::table_frame(scene.table);
  nlohmann::json gt;
  gt["seed"] = seed;
  gt["width"] = cloud.width();
  gt["height"] = cloud.height();
  gt["frame"] = "sensor: x right, y down, z forward, metres";
  gt["pose_convention"] =
      "row-major 4x4 sensor_from_object; origin at the footprint centre on the table, z = table "
      "normal";
  gt["labels"] = {{"none", simulation::LABEL_NONE},
                  {"table", simulation::LABEL_TABLE},
                  {"floor", simulation::LABEL_FLOOR},
                  {"object_base", simulation::OBJECT_LABEL_BASE}};
  nlohmann::json corners = nlohmann::json::array();
  for (const auto& c : simulation::table_corners(scene.table)) { corners.push_back(vec(c)); }
  gt["table"] = {{"normal", vec(f.normal)},
                 {"d", f.d},
                 {"corners", corners},
                 {"distance_m", scene.table.distance_m},
                 {"tilt_deg", scene.table.tilt_rad * RAD_TO_DEG},
                 {"width_m", scene.table.width_m},
                 {"depth_m", scene.table.depth_m},
                 {"floor_drop_m", scene.table.floor_drop_m}};
  std::vector<std::size_t> visible(scene.objects.size(), 0);
  for (std::uint32_t l : cloud.label()) {
    const int id = simulation::object_of_label(l);
    if (id >= 0) { ++visible[static_cast<std::size_t>(id)]; }
  }
  gt["objects"] = nlohmann::json::array();
  for (std::size_t i = 0; i < scene.objects.size(); ++i) {
    const simulation::PlacedObject& o = scene.objects[i];
    gt["objects"].push_back({{"id", i},
                             {"label", simulation::OBJECT_LABEL_BASE + i},
                             {"category", simulation::category_name(o.model.category)},
                             {"instance", o.model.instance},
                             {"pose", simulation::object_pose(f, o)},
                             {"yaw_rad", o.yaw},
                             {"table_xy", {o.table_x, o.table_y}},
                             {"footprint_radius_m", o.model.footprint_radius},
                             {"height_m", o.model.height},
                             {"visible_points", visible[i]}});
  }
  return gt;
}

struct SynthArgs {
  std::uint32_t objects = 6;
  std::uint64_t seed = 1;
  std::string out;
  bool touching = false;
  bool stacked = false;
  bool no_floor = false;
  std::string categories;
  std::string ground_truth;
};

void run_synth(const SynthArgs& a) {
  simulation::SceneConfig config;
  config.objects = a.objects;
  config.touching = a.touching;
  config.stacked = a.stacked;
  config.floor = !a.no_floor;
  config.categories = parse_categories(a.categories);
  const simulation::Scene scene = simulation::make_scene(config, a.seed);
  kernels::PointCloud cloud;
  core::Rng rng(~a.seed);
  simulation::render_scene(scene, simulation::RenderOptions{}, rng, cloud);
  if (auto written = formats::write_pcd(cloud, a.out); !written) {
    std::cerr << written.error().to_string() << "\n";
    throw CLI::RuntimeError(EXIT_FAILURE_GENERIC);
  }
  const nlohmann::json gt = ground_truth(scene, cloud, a.seed);
  if (!a.ground_truth.empty()) {
    if (auto written = core::write_whole_file(a.ground_truth, gt.dump(2) + "\n"); !written) {
      std::cerr << written.error() << ": cannot write the ground truth file\n";
      throw CLI::RuntimeError(EXIT_FAILURE_GENERIC);
    }
  }
  std::size_t valid = 0;
  for (float z : cloud.z()) { valid += !std::isnan(z); }
  std::cout << a.out << ": " << cloud.width() << "x" << cloud.height() << ", " << valid
            << " valid points; table at " << scene.table.distance_m << " m, tilt "
            << scene.table.tilt_rad * RAD_TO_DEG << " deg; " << scene.objects.size() << " of "
            << a.objects << " objects placed:";
  for (const auto& o : gt["objects"]) {
    std::cout << " " << o["category"].get<std::string>() << "#" << o["instance"] << "("
              << o["visible_points"] << " pts)";
  }
  std::cout << "\n";
}

struct DatasetArgs {
  std::string out;
  std::string categories;
  std::uint32_t instances = 3;
  std::uint32_t views = 10;
  std::uint64_t seed = 1;
};

void run_dataset(const DatasetArgs& a) {
  simulation::DatasetConfig config;
  config.categories = parse_categories(a.categories);
  config.instances = a.instances;
  config.views = a.views;
  config.seed = a.seed;
  const auto summary_result = simulation::write_object_dataset(config, a.out);
  if (!summary_result) {
    std::cerr << summary_result.error().to_string() << "\n";
    throw CLI::RuntimeError(summary_result.error().code ==
                                    simulation::DatasetError::Code::BAD_CONFIG
                                ? EXIT_USAGE
                                : EXIT_FAILURE_GENERIC);
  }
  const simulation::DatasetSummary& s = summary_result.value();
  std::cout << a.out << ": " << s.categories << " categories x " << a.instances << " instances x "
            << a.views << " views = " << s.files << " views written, " << s.points
            << " points (fewest in one view: " << s.min_points << ")\n";
}

}  // namespace

void add_synth_command(CLI::App& app) {
  auto synth_args = std::make_shared<SynthArgs>();
  CLI::App* synth = app.add_subcommand(
      "synth", "Render one synthetic Kinect v1 tabletop frame (organized PCD with rgb and label)");
  synth->add_option("--objects", synth_args->objects, "objects to place (fewer if they do not fit)")
      ->check(CLI::Range(0, static_cast<int>(simulation::MAX_SCENE_OBJECTS)));
  synth->add_option("--seed", synth_args->seed, "seed: same seed, same bytes");
  synth->add_option("--out", synth_args->out, "output PCD file")->required();
  synth->add_flag("--touching", synth_args->touching, "place objects in touching pairs");
  synth->add_flag("--stacked", synth_args->stacked,
                  "boxes in stacks of two: every second box lies on the previous one");
  synth->add_flag("--no-floor", synth_args->no_floor, "leave the floor out");
  synth->add_option("--categories", synth_args->categories,
                    "comma-separated categories (default: the 12 scene categories)");
  synth->add_option("--ground-truth", synth_args->ground_truth,
                    "write the scene's ground truth as JSON here");
  synth->callback([synth_args] { run_synth(*synth_args); });

  auto ds_args = std::make_shared<DatasetArgs>();
  CLI::App* ds = app.add_subcommand(
      "synth-dataset", "Write segmented object views as DIR/<category>/<instance>/view_NNN.pcd");
  ds->add_option("--out", ds_args->out, "output directory")->required();
  ds->add_option("--categories", ds_args->categories,
                 "comma-separated categories, each named once (default: all)");
  ds->add_option("--instances", ds_args->instances, "instances per category")
      ->check(CLI::Range(1, 1000));
  ds->add_option("--views", ds_args->views, "views per instance")->check(CLI::Range(1, 10000));
  ds->add_option("--seed", ds_args->seed, "seed for shapes, viewpoints and noise");
  ds->callback([ds_args] { run_dataset(*ds_args); });
}

}  // namespace orthoflow::apps
