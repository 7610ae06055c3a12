#pragma once
// Detection quality of a cluster labelling (id or -1 per pixel, SegmentationResult::labels)
// against mOSD ground truth, used by seg_chain_test and the vs_pcl benchmark: the product's own
// scoring (evaluation/segmentation_score.hpp, the rule `orthoflow evaluate-segmentation` applies)
// after turning cluster k into predicted object k + 2.
#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

#include "evaluation/segmentation_score.hpp"

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

/// @p gt_label: mOSD labels; @p cluster: id or -1, same pixels.
inline Quality evaluate(std::span<const std::uint32_t> gt_label,
                        std::span<const std::int32_t> cluster) {
  std::vector<std::uint32_t> predicted(cluster.size());
  for (std::size_t i = 0; i < cluster.size(); ++i) {
    predicted[i] = cluster[i] >= 0 ? static_cast<std::uint32_t>(cluster[i]) + 2U : 0U;
  }
  const auto c = evaluation::score_objects(gt_label, predicted);
  return Quality{c.truth, c.predicted, c.matched, c.over, c.under};
}

}  // namespace orthoflow::testing
