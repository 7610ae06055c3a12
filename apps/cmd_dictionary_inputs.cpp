// `orthoflow dictionary build`, its inputs: the object views (*.pcd) under --from, and the objects
// the product's segmentation finds in the frames under --scenes (thesis chapter 3's unsupervised
// object discovery). The options, build and show are in cmd_dictionary.cpp.
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "apps/commands.hpp"
#include "apps/dictionary_cli.hpp"
#include "apps/graph_segmentation.hpp"
#include "formats/pcd_io.hpp"
#include "kernels/frame_labels.hpp"
#include "kernels/pinhole_regrid.hpp"
#include "kernels/segmentation_chain.hpp"

namespace orthoflow::apps::dictionary_cli {

/// Every *.pcd under the directories (or the files named), sorted: the pool's order.
std::vector<std::filesystem::path> views_under(const std::vector<std::string>& roots) {
  std::vector<std::filesystem::path> out;
  for (const std::string& root : roots) {
    std::error_code ec;
    if (std::filesystem::is_regular_file(root, ec)) {
      out.emplace_back(root);
      continue;
    }
    if (!std::filesystem::is_directory(root, ec))
      fail(root + " is not a directory", EXIT_BAD_INPUT);
    for (auto it = std::filesystem::recursive_directory_iterator(root, ec);
         !ec && it != std::filesystem::recursive_directory_iterator(); it.increment(ec)) {
      if (it->is_regular_file() && it->path().extension() == ".pcd") out.push_back(it->path());
    }
    if (ec) fail("cannot list " + root + ": " + ec.message(), EXIT_BAD_INPUT);
  }
  std::sort(out.begin(), out.end());
  out.erase(std::unique(out.begin(), out.end()), out.end());
  return out;
}

/// The objects the product's segmentation (the graph's preprocess, table and objects nodes) finds
/// in every frame under @p roots, in frame order and candidate order: their finite points.
std::vector<kernels::PointCloud> objects_in_scenes(const std::vector<std::string>& roots,
                                                   const std::string& graph, std::size_t& frames) {
  auto seg = segmentation_of_graph_arg(graph);
  if (!seg) fail(seg.error(), EXIT_BAD_INPUT);
  const auto files = views_under(roots);
  if (files.empty()) fail("no *.pcd frame under the given --scenes", EXIT_BAD_INPUT);
  frames = files.size();
  std::vector<kernels::PointCloud> objects;
  std::unique_ptr<kernels::SegmentationChain> chain;
  std::size_t chain_points = 0;
  std::vector<std::uint32_t> labels;
  for (const std::filesystem::path& file : files) {
    auto cloud = formats::read_pcd(file);
    if (!cloud) fail(file.string() + ": " + cloud.error().to_string(), EXIT_BAD_INPUT);
    if (!cloud->organized()) {
      if (auto grid = kernels::organize_if_pinhole(*cloud); !grid)
        fail(file.string() + ": not a camera frame (" +
                 std::string(kernels::to_string(grid.error())) + ")",
             EXIT_BAD_INPUT);
    }
    if (!chain || cloud->size() > chain_points) {
      chain_points = cloud->size();
      chain =
          std::make_unique<kernels::SegmentationChain>(chain_points, seg->stages, seg->candidates);
    }
    auto result = chain->run(cloud->view());
    if (!result) fail(file.string() + ": " + result.error().to_string(), EXIT_BAD_INPUT);
    // Per-point labels need the organized chain (a voxel-grid chain labels voxels, not points).
    if (!result->organized)
      fail(file.string() + ": the graph's segmentation is not the organized chain", EXIT_BAD_INPUT);
    // The one point-to-object rule (kernels::frame_labels, as `segment --labels-out` writes it).
    labels.resize(cloud->size());
    kernels::frame_labels(cloud->points(), result->plane.plane, seg->stages.ransac.tau,
                          seg->stages.roi, result->labels, result->candidate_of, labels);
    const std::size_t first = objects.size();
    std::vector<std::vector<std::size_t>> members(result->candidates.size());
    const auto points = cloud->points();
    for (std::size_t i = 0; i < labels.size(); ++i) {
      const std::size_t k = labels[i] - kernels::FIRST_OBJECT_LABEL;  // wraps for 0 and 1
      if (labels[i] >= kernels::FIRST_OBJECT_LABEL && k < members.size() &&
          std::isfinite(points.x[i]) && std::isfinite(points.y[i]) && std::isfinite(points.z[i]))
        members[k].push_back(i);
    }
    objects.resize(first + members.size());
    for (std::size_t k = 0; k < members.size(); ++k) {
      kernels::PointCloud& o = objects[first + k];
      o.resize_unorganized(members[k].size());
      for (std::size_t n = 0; n < members[k].size(); ++n) {
        o.x()[n] = points.x[members[k][n]];
        o.y()[n] = points.y[members[k][n]];
        o.z()[n] = points.z[members[k][n]];
      }
    }
  }
  return objects;
}

}  // namespace orthoflow::apps::dictionary_cli
