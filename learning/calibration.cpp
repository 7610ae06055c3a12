#include "learning/calibration.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

#include "kernels/distance.hpp"

namespace orthoflow::learning {
namespace {

// Every stored view in one dims x V structure-of-arrays matrix, with the category of each column.
struct AllViews {
  std::vector<float> soa;
  std::vector<std::size_t> category;  // index into the categories span
  std::size_t count = 0;
};

AllViews gather(std::span<const RestoredCategory> categories, std::size_t dims) {
  AllViews all;
  for (const RestoredCategory& c : categories) { all.count += c.views.count(); }
  all.soa.assign(dims * all.count, 0.0F);
  std::size_t col = 0;
  for (std::size_t k = 0; k < categories.size(); ++k) {
    for (std::size_t v = 0; v < categories[k].views.count(); ++v, ++col) {
      const std::span<const float> x = categories[k].views.view(v);
      for (std::size_t d = 0; d < dims; ++d) { all.soa[d * all.count + col] = x[d]; }
      all.category.push_back(k);
    }
  }
  return all;
}

// Per-category view counts and pairwise-distance sums; count 0 marks a category as absent.
struct IcdInputs {
  std::vector<std::size_t> count;
  std::vector<double> pair_sum;
};

// The ICD in use for each category and their mean: the rules of InstanceLearner
// (instance_learner.hpp).
std::vector<float> icds(const IcdInputs& in, const InstanceConfig& cfg, float& mean) {
  double defined_sum = 0.0;
  std::size_t defined = 0;
  std::vector<float> out(in.count.size(), 0.0F);
  for (std::size_t k = 0; k < out.size(); ++k) {
    if (in.count[k] >= 2) {
      const double n = static_cast<double>(in.count[k]);
      out[k] = std::max(static_cast<float>(2.0 * in.pair_sum[k] / (n * (n - 1.0))), cfg.min_icd);
      defined_sum += static_cast<double>(out[k]);
      ++defined;
    }
  }
  const float fallback = defined > 0
                             ? static_cast<float>(defined_sum / static_cast<double>(defined))
                             : cfg.default_icd;
  double sum = 0.0;
  std::size_t present = 0;
  for (std::size_t k = 0; k < out.size(); ++k) {
    if (in.count[k] == 1) { out[k] = fallback; }
    if (in.count[k] >= 1) {
      sum += static_cast<double>(out[k]);
      ++present;
    }
  }
  mean = present > 0 ? static_cast<float>(sum / static_cast<double>(present)) : cfg.default_icd;
  return out;
}

// NOCD of the view in column @p self to category @p k (excluding column self), from its distance
// row.
float nocd(std::span<const float> row, const AllViews& all, std::size_t self, std::size_t k,
           float icd, float mean_icd, const InstanceConfig& cfg) {
  float min_d = std::numeric_limits<float>::infinity();
  double sum = 0.0;
  std::size_t n = 0;
  for (std::size_t j = 0; j < all.count; ++j) {
    if (j == self || all.category[j] != k) { continue; }
    min_d = std::min(min_d, row[j]);
    sum += static_cast<double>(row[j]);
    ++n;
  }
  if (n == 0) { return std::numeric_limits<float>::infinity(); }
  if (!cfg.normalise) { return min_d; }
  if (cfg.approach == NocdApproach::MIN_DISTANCE) { return min_d / icd; }
  return static_cast<float>(2.0 * sum / static_cast<double>(n)) / (icd + mean_icd);
}

// The midpoint threshold between sorted samples with the best balanced accuracy (ties: smallest).
Calibration best_threshold(std::vector<float> known, std::vector<float> unknown) {
  std::sort(known.begin(), known.end());
  std::sort(unknown.begin(), unknown.end());
  std::vector<float> all = known;
  all.insert(all.end(), unknown.begin(), unknown.end());
  std::sort(all.begin(), all.end());
  std::vector<float> candidates{all.front() * 0.5F};
  for (std::size_t i = 0; i + 1 < all.size(); ++i) {
    if (all[i] < all[i + 1]) { candidates.push_back(0.5F * (all[i] + all[i + 1])); }
  }
  candidates.push_back(all.back() * 1.5F + 1e-6F);
  Calibration best{0.0F, -1.0F, known.size(), unknown.size()};
  for (const float ct : candidates) {
    const auto accepted =
        static_cast<double>(std::upper_bound(known.begin(), known.end(), ct) - known.begin());
    const auto rejected =
        static_cast<double>(unknown.end() - std::upper_bound(unknown.begin(), unknown.end(), ct));
    const auto balanced =
        static_cast<float>(0.5 * (accepted / static_cast<double>(known.size()) +
                                  rejected / static_cast<double>(unknown.size())));
    if (balanced > best.balanced_accuracy) {
      best.threshold = ct;
      best.balanced_accuracy = balanced;
    }
  }
  return best;
}

}  // namespace

const char* to_string(CalibrationError error) noexcept {
  switch (error) {
    case CalibrationError::TOO_FEW_CATEGORIES:
      return "calibration needs at least two categories";
    case CalibrationError::TOO_FEW_VIEWS:
      return "calibration needs a category with at least two views";
  }
  return "unknown calibration error";
}

Result<Calibration, CalibrationError> calibrate_threshold(
    std::span<const RestoredCategory> categories, const InstanceConfig& cfg) {
  if (categories.size() < 2) { return err(CalibrationError::TOO_FEW_CATEGORIES); }
  const std::size_t dims = cfg.descriptor_length;
  const AllViews all = gather(categories, dims);
  const kernels::DescriptorMatrixView matrix{all.soa, dims, all.count, all.count};
  std::vector<std::vector<float>> rows(all.count, std::vector<float>(all.count));
  IcdInputs base{std::vector<std::size_t>(categories.size(), 0),
                 std::vector<double>(categories.size(), 0.0)};
  std::vector<std::size_t> first(categories.size(), 0);
  for (std::size_t t = 0, col = 0; t < categories.size(); col += categories[t].views.count(), ++t) {
    first[t] = col;
  }
  for (std::size_t t = 0; t < all.count; ++t) {
    const std::size_t k = all.category[t];
    kernels::distances(categories[k].views.view(t - first[k]), matrix, kernels::Metric::L2,
                       rows[t]);
    ++base.count[k];
    for (std::size_t j = first[k]; j < t; ++j) {
      base.pair_sum[k] += static_cast<double>(rows[t][j]);
    }
  }
  std::vector<float> known;
  std::vector<float> unknown;
  for (std::size_t t = 0; t < all.count; ++t) {
    const std::size_t c = all.category[t];
    if (base.count[c] < 2) { continue; }
    IcdInputs reduced = base;  // C without T: the "known" situation
    --reduced.count[c];
    for (std::size_t j = first[c]; j < first[c] + base.count[c]; ++j) {
      reduced.pair_sum[c] -= j == t ? 0.0 : static_cast<double>(rows[t][j]);
    }
    float mean = 0.0F;
    const std::vector<float> icd_known = icds(reduced, cfg, mean);
    known.push_back(nocd(rows[t], all, t, c, icd_known[c], mean, cfg));
    IcdInputs removed = base;  // C never taught: the "unknown" situation
    removed.count[c] = 0;
    const std::vector<float> icd_unknown = icds(removed, cfg, mean);
    float nearest_other = std::numeric_limits<float>::infinity();
    for (std::size_t k = 0; k < categories.size(); ++k) {
      if (k != c) {
        nearest_other =
            std::min(nearest_other, nocd(rows[t], all, t, k, icd_unknown[k], mean, cfg));
      }
    }
    unknown.push_back(nearest_other);
  }
  if (known.empty()) { return err(CalibrationError::TOO_FEW_VIEWS); }
  return best_threshold(std::move(known), std::move(unknown));
}

}  // namespace orthoflow::learning
