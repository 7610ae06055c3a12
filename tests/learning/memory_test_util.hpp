#pragma once
// Helpers for the perceptual-memory tests: a fresh store directory and deterministic GOOD-like
// views.
#include <gtest/gtest.h>

#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "learning/perceptual_memory.hpp"

namespace orthoflow::learning::test {

/// A fresh, empty directory under the build tree, named after the running test.
inline std::filesystem::path fresh_dir(const std::string& tag = "") {
  const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
  const std::filesystem::path dir =
      std::filesystem::path(ORTHOFLOW_BINARY_DIR) / "test_stores" /
      (std::string(info->test_suite_name()) + "." + info->name() + tag);
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir.parent_path());
  return dir;
}

/// Memory configuration with small descriptors (bins 5: 75 values).
inline MemoryConfig small_config(LearnerKind kind = LearnerKind::INSTANCE) {
  MemoryConfig cfg;
  cfg.descriptor.good.bins = 5;
  cfg.learner = kind;
  return cfg;
}

/// A bag-of-words dictionary of @p words seeded words (spin images of width 4: 45 values).
inline std::shared_ptr<const kernels::VisualDictionary> test_dictionary(std::size_t words = 75,
                                                                        std::uint64_t seed = 1) {
  auto d = std::make_shared<kernels::VisualDictionary>();
  d->words = words;
  d->dims = kernels::spin_image_bins(4);
  d->data.resize(d->words * d->dims);
  for (std::size_t i = 0; i < d->data.size(); ++i)
    d->data[i] = static_cast<float>((i * 2654435761ULL + seed * 97ULL) % 1000ULL) / 1000.0F;
  d->id = kernels::dictionary_id(*d);
  d->provenance = "memory tests";
  return d;
}

/// small_config() as a bag of words over test_dictionary(): descriptors of 75 values too.
inline MemoryConfig bow_config(LearnerKind kind = LearnerKind::INSTANCE, std::uint64_t seed = 1) {
  MemoryConfig cfg = small_config(kind);
  cfg.descriptor = kernels::DescriptorSpec::make_bow(test_dictionary(75, seed));
  cfg.descriptor.good.bins = 5;
  return cfg;
}

/// A histogram view of @p length values: three blocks summing to 1, peaked at bin @p peak of each
/// block, with a small seeded wobble so that views of one category differ.
inline ViewRecord make_view(std::size_t length, std::size_t peak, std::uint64_t seed) {
  ViewRecord v;
  v.descriptor.assign(length, 0.0F);
  const std::size_t block = length / 3;
  for (std::size_t b = 0; b < 3; ++b) {
    const float wobble =
        0.05F * static_cast<float>((seed * 2654435761ULL + b * 97ULL) % 7ULL) / 7.0F;
    v.descriptor[b * block + peak % block] = 0.8F - wobble;
    v.descriptor[b * block + (peak + 1) % block] = 0.2F + wobble;
  }
  for (std::size_t i = 0; i < 16; i += 5) { v.frame[i] = 1.0F; }
  v.bbox = {0.1F, 0.05F, 0.02F};
  v.track_id = seed;
  v.stamp_ns = static_cast<std::int64_t>(seed);
  return v;
}

}  // namespace orthoflow::learning::test
