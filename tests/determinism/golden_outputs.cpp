// Computes the golden sections (see golden_outputs.hpp). Floats are written with 9 significant
// digits, which round-trips a float exactly, so the x86 golden file holds the exact values it
// computed.
#include "golden_outputs.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <functional>
#include <span>
#include <stdexcept>
#include <vector>

#include "core/fnv.hpp"
#include "formats/pcd_io.hpp"
#include "kernels/good.hpp"
#include "kernels/segmentation_chain.hpp"
#include "kernels/simd_arch.hpp"
#include "simulation/world/object_catalog.hpp"
#include "simulation/world/object_dataset.hpp"
#include "simulation/world/synthetic_scene.hpp"

namespace orthoflow::testing {
namespace {

namespace ofmt = orthoflow::formats;
namespace osim = orthoflow::simulation;
namespace ok = orthoflow::kernels;

template <class T>
std::string fnv1a64(std::span<const T> values) {
  std::uint64_t h = orthoflow::core::FNV_OFFSET;
  const auto* bytes = reinterpret_cast<const std::uint8_t*>(values.data());
  for (std::size_t i = 0; i < values.size_bytes(); ++i) h = orthoflow::core::fnv1a(h, bytes[i]);
  char text[17];
  std::snprintf(text, sizeof text, "%016llx", static_cast<unsigned long long>(h));
  return text;
}

// The scene `orthoflow synth --seed S` writes (apps/cmd_synth.cpp): make_scene(seed), noise from
// ~seed.
ok::PointCloud render_seeded_scene(std::uint64_t seed) {
  const osim::Scene scene = osim::make_scene(osim::SceneConfig{}, seed);
  ok::PointCloud cloud;
  core::Rng rng(~seed);
  osim::render_scene(scene, osim::RenderOptions{}, rng, cloud);
  return cloud;
}

// Rounds through float's shortest exact decimal so the JSON file stays readable and exact.
double exact(float v) {
  char text[32];
  std::snprintf(text, sizeof text, "%.9g", static_cast<double>(v));
  return std::strtod(text, nullptr);
}

nlohmann::json good_entry(const ok::PointCloud& cloud) {
  ok::GoodConfig cfg;
  ok::GoodScratch scratch(cfg.bins);
  std::vector<float> descriptor(3 * cfg.bins * cfg.bins);
  auto good_result = ok::compute_good(cloud.points(), cfg, scratch, descriptor);
  if (!good_result) {
    throw std::runtime_error(std::string("compute_good: ") + ok::to_string(good_result.error()));
  }
  nlohmann::json entry;
  entry["points_used"] = good_result->points_used;
  entry["flags"] = good_result->flags;
  entry["signs"] = good_result->signs;
  nlohmann::json values = nlohmann::json::array();
  for (float v : descriptor) { values.push_back(exact(v)); }
  entry["descriptor"] = std::move(values);
  return entry;
}

}  // namespace

nlohmann::json golden_scenes() {
  nlohmann::json out = nlohmann::json::object();
  for (unsigned long long seed : GOLDEN_SCENE_SEEDS) {
    const ok::PointCloud cloud = render_seeded_scene(seed);
    std::size_t finite = 0;
    for (std::size_t i = 0; i < cloud.size(); ++i) {
      finite += std::isfinite(cloud.z()[i]) ? 1U : 0U;
    }
    out[std::to_string(seed)] = {{"points", cloud.size()},         {"finite", finite},
                                 {"x", fnv1a64(cloud.x())},        {"y", fnv1a64(cloud.y())},
                                 {"z", fnv1a64(cloud.z())},        {"rgb", fnv1a64(cloud.rgb())},
                                 {"label", fnv1a64(cloud.label())}};
  }
  return out;
}

nlohmann::json golden_segmentation() {
  nlohmann::json out = nlohmann::json::object();
  for (unsigned long long seed : GOLDEN_SCENE_SEEDS) {
    const ok::PointCloud cloud = render_seeded_scene(seed);
    ok::SegmentationChain chain(cloud.size(), ok::SegmentationParams{});
    auto seg_result = chain.run(cloud.view());
    if (!seg_result) {
      throw std::runtime_error("segmentation of scene " + std::to_string(seed) + ": " +
                               seg_result.error().to_string());
    }
    std::vector<std::size_t> sizes;
    for (const ok::ClusterStats& c : seg_result->clusters) { sizes.push_back(c.points); }
    std::sort(sizes.begin(), sizes.end(), std::greater<>());
    const ok::Plane& p = seg_result->plane.plane;
    out[std::to_string(seed)] = {
        {"normal", {exact(p.normal[0]), exact(p.normal[1]), exact(p.normal[2])}},
        {"d", exact(p.d)},
        {"inliers", seg_result->plane.inliers},
        {"cluster_sizes", sizes}};
  }
  return out;
}

nlohmann::json golden_good(const std::string& shared_dir) {
  nlohmann::json out = nlohmann::json::object();
  std::vector<std::filesystem::path> files;
  for (const auto& e : std::filesystem::directory_iterator(shared_dir + "/data/objects")) {
    if (e.path().extension() == ".pcd") { files.push_back(e.path()); }
  }
  std::sort(files.begin(), files.end());  // directory order is not portable
  for (const auto& f : files) {
    auto cloud_result = ofmt::read_pcd(f);
    if (!cloud_result) {
      throw std::runtime_error(f.string() + ": " + cloud_result.error().to_string());
    }
    out[f.filename().string()] = good_entry(*cloud_result);
  }
  // A rendered view: the renderer is bit-exact, so this also checks GOOD on a known-identical
  // input.
  const osim::ObjectModel mug = osim::make_object_model(osim::Category::MUG, 1, 7);
  ok::PointCloud frame, view;
  core::Rng rng(42);
  osim::render_object_view(mug, osim::ViewSpec{0.7, 0.4, 0.9}, osim::RenderOptions{}, rng, frame,
                           view);
  out["synthetic_mug"] = good_entry(view);
  return out;
}

nlohmann::json golden_all(const std::string& shared_dir) {
  return {{"generated_on", ok::simd_arch_name()},
          {"scenes", golden_scenes()},
          {"segmentation", golden_segmentation()},
          {"good", golden_good(shared_dir)},
          {"learning", golden_learning()}};
}

}  // namespace orthoflow::testing
