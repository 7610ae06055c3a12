#pragma once
// Hand-made datasets for the protocol tests: categories whose views are given descriptors (length
// 3, i.e. GOOD with 1 bin), so the expected learner answers, and hence NLC / QCI / GCA, can be
// worked out by hand.
#include <cstdint>
#include <string>
#include <vector>

#include "evaluation/dataset.hpp"
#include "evaluation/descriptors.hpp"
#include "evaluation/variant.hpp"

namespace orthoflow::evaluation::testing {

/// One category: its view count and the (identical) descriptor of every view.
struct HandCategory {
  std::string name;
  std::size_t views;
  std::vector<float> descriptor;  // 3 values, a histogram (non-negative, sums to 1)
};

struct HandMade {
  Dataset dataset;
  DescriptorTable table;
};

inline HandMade hand_made(const std::vector<HandCategory>& cats) {
  HandMade h;
  h.table.length = 3;
  for (std::uint32_t c = 0; c < cats.size(); ++c) {
    h.dataset.categories.push_back(cats[c].name);
    h.dataset.instances.push_back(cats[c].name + "/i0");
    for (std::size_t v = 0; v < cats[c].views; ++v) {
      h.dataset.views.push_back(
          DatasetView{c, c, cats[c].name + "/i0/v" + std::to_string(v) + ".pcd"});
      h.table.values.insert(h.table.values.end(), cats[c].descriptor.begin(),
                            cats[c].descriptor.end());
    }
  }
  return h;
}

/// Plain nearest neighbour on 1-bin descriptors (length 3).
inline Variant nn_variant() {
  Variant v;
  v.bins = 1;
  return v;
}

inline Variant bayes_variant() {
  Variant v = nn_variant();
  v.learner = LearnerKind::BAYES;
  return v;
}

inline const std::vector<float> E0{1.0F, 0.0F, 0.0F};
inline const std::vector<float> E1{0.0F, 1.0F, 0.0F};
inline const std::vector<float> E2{0.0F, 0.0F, 1.0F};
inline const std::vector<float> E3{0.5F, 0.5F, 0.0F};

}  // namespace orthoflow::evaluation::testing
