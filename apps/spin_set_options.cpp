#include "apps/spin_set_options.hpp"

namespace orthoflow::apps {

void add_spin_set_options(CLI::App* cmd, kernels::SpinSetParams& spin) {
  cmd->add_option("--spin-keypoints", spin.max_keypoints,
                  "spin: the most spin images a view's set keeps (evenly spaced)")
      ->check(CLI::Range(1, static_cast<int>(kernels::MAX_SET_KEYPOINTS)));
  cmd->add_option(
         "--spin-width", spin.features.spin.image_width,
         "spin: the spin images' width IW (default 8, the thesis's sets; the bag of words: 4)")
      ->check(CLI::Range(1, static_cast<int>(kernels::MAX_SPIN_IMAGE_WIDTH)));
  cmd->add_option("--spin-support", spin.features.spin.support_length,
                  "spin: the support length SL in metres (default 0.10, the thesis's sets)")
      ->check(CLI::Range(0.001, 1.0));
  cmd->add_option(
         "--spin-leaf", spin.features.keypoint_leaf,
         "spin: the keypoints' voxel size VS in metres (default 0.04, the thesis's approach II)")
      ->check(CLI::Range(0.001, 1.0));
}

}  // namespace orthoflow::apps
