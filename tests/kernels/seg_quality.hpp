#pragma once
// Detection quality of a labelling against the mOSD ground truth (used by seg_chain_test and the
// vs_pcl benchmark). Rule: a cluster detects ground-truth object k when their pixel sets have
// IoU >= 0.5 (then the match is one-to-one). Over-segmented object: >= 2 clusters each hold >= 10 %
// of its pixels. Under-segmenting cluster: >= 2 objects each put >= 10 % of their pixels in it.
#include <cstddef>
#include <cstdint>
#include <map>
#include <span>

namespace orthoflow::testing {

struct Quality {
  std::size_t gt_objects = 0, clusters = 0, matched = 0, over = 0, under = 0;
  [[nodiscard]] double precision() const {
    return clusters == 0 ? 0.0 : double(matched) / double(clusters);
  }
  [[nodiscard]] double recall() const {
    return gt_objects == 0 ? 1.0 : double(matched) / double(gt_objects);
  }
};

/// @p gt_label: mOSD labels (object k = label / 10 for label >= 20); @p cluster: id or -1, same
/// pixels.
inline Quality evaluate(std::span<const std::uint32_t> gt_label,
                        std::span<const std::int32_t> cluster) {
  std::map<std::uint32_t, std::size_t> obj_size;
  std::map<std::int32_t, std::size_t> cl_size;
  std::map<std::pair<std::uint32_t, std::int32_t>, std::size_t> both;
  for (std::size_t i = 0; i < gt_label.size(); ++i) {
    const std::uint32_t obj = gt_label[i] >= 20 ? gt_label[i] / 10 : 0;
    if (obj != 0) { ++obj_size[obj]; }
    if (cluster[i] >= 0) { ++cl_size[cluster[i]]; }
    if (obj != 0 && cluster[i] >= 0) { ++both[{obj, cluster[i]}]; }
  }
  Quality q;
  q.gt_objects = obj_size.size();
  q.clusters = cl_size.size();
  std::map<std::uint32_t, int> parts_of_obj;
  std::map<std::int32_t, int> objs_in_cl;
  for (const auto& [key, n] : both) {
    const double iou = double(n) / double(obj_size[key.first] + cl_size[key.second] - n);
    if (iou >= 0.5) { ++q.matched; }
    if (double(n) >= 0.1 * double(obj_size[key.first])) {
      ++parts_of_obj[key.first];
      ++objs_in_cl[key.second];
    }
  }
  for (const auto& [obj, parts] : parts_of_obj) { q.over += parts >= 2 ? 1U : 0U; }
  for (const auto& [cl, objs] : objs_in_cl) { q.under += objs >= 2 ? 1U : 0U; }
  return q;
}

}  // namespace orthoflow::testing
