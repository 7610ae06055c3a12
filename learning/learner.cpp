#include "learning/learner.hpp"

#include "core/label_text.hpp"

#include "learning/detail/learner_common.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <string>

namespace orthoflow::learning {

const char* to_string(LearnError error) noexcept {
  switch (error) {
    case LearnError::EMPTY_LABEL:
      return "empty label: a category needs a name";
    case LearnError::BAD_CHARACTERS:
      return "label is not valid UTF-8 in Unicode NFC, or holds a control character (newline, tab, "
             "NUL, ...) or an invisible or direction-control one (U+200B, U+202E, ...)";
    case LearnError::LABEL_TOO_LONG:
      return "label longer than 63 bytes";
    case LearnError::NO_VIEWS:
      return "no view to learn from (empty descriptor batch)";
    case LearnError::WRONG_LENGTH:
      return "descriptor length differs from the learner's descriptor_length";
    case LearnError::NOT_FINITE:
      return "descriptor holds a NaN or infinite value";
    case LearnError::NEGATIVE_VALUE:
      return "histogram descriptor holds a negative value";
    case LearnError::UNKNOWN_LABEL:
      return "no category has this label";
    case LearnError::DUPLICATE_ID:
      return "two restored categories share an id or a label";
    case LearnError::NOT_LAST_VIEWS:
      return "those views are not the category's last views";
    case LearnError::NOT_A_SPIN_SET:
      return "not a set of spin images: the count is not a whole number from 1 to the set's "
             "capacity, or a value after the last image is not zero";
    case LearnError::NOT_WORD_COUNTS:
      return "not a view's word counts: a value is not a whole number, or the view has no word or "
             "more words than the learner takes";
  }
  return "unknown learn error";
}

Result<void, LearnError> validate_label(std::string_view label) noexcept {
  switch (core::check_label(label)) {  // the one label rule (core/label_text.hpp)
    case core::LabelProblem::NONE:
      return {};
    case core::LabelProblem::EMPTY:
      return err(LearnError::EMPTY_LABEL);
    case core::LabelProblem::TOO_LONG:
      return err(LearnError::LABEL_TOO_LONG);
    case core::LabelProblem::NOT_UTF8:
    case core::LabelProblem::CONTROL_CHARACTER:
    case core::LabelProblem::INVISIBLE_CHARACTER:
    case core::LabelProblem::NOT_NFC:
      return err(LearnError::BAD_CHARACTERS);
  }
  return err(LearnError::BAD_CHARACTERS);
}

Result<void, LearnError> validate_batch(DescriptorBatch views, std::size_t length,
                                        bool histograms) noexcept {
  if (views.values.empty()) { return err(LearnError::NO_VIEWS); }
  if (views.length != length || views.values.size() % length != 0) {
    return err(LearnError::WRONG_LENGTH);
  }
  for (const float v : views.values) {
    if (!std::isfinite(v)) { return err(LearnError::NOT_FINITE); }
    if (histograms && v < 0.0F) { return err(LearnError::NEGATIVE_VALUE); }
  }
  return {};
}

float category_icds(std::span<const PairSum> categories, float min_icd, float default_icd,
                    std::vector<float>& icd) {
  const auto measured_icd = [min_icd](const PairSum& c) {
    const double n = static_cast<double>(c.views);
    return std::max(2.0 * c.sum / (n * (n - 1.0)), static_cast<double>(min_icd));
  };
  double measured_sum = 0.0;
  std::size_t measured = 0;
  for (const PairSum& c : categories) {
    if (c.views < 2) continue;
    measured_sum += measured_icd(c);
    ++measured;
  }
  const double fallback = measured > 0 ? measured_sum / static_cast<double>(measured)
                                       : static_cast<double>(default_icd);
  double all = 0.0;
  icd.clear();
  for (const PairSum& c : categories) {
    const double value = c.views >= 2 ? measured_icd(c) : fallback;
    icd.push_back(static_cast<float>(value));
    all += value;
  }
  return categories.empty() ? default_icd
                            : static_cast<float>(all / static_cast<double>(categories.size()));
}

void enforce_icd_config(float default_icd, float min_icd, float ct, const char* who) {
  OF_ENFORCE(
      default_icd > 0.0F && std::isfinite(default_icd) && min_icd > 0.0F && std::isfinite(min_icd),
      (std::string(who) + ": default_icd and min_icd must be finite and > 0").c_str());
  OF_ENFORCE(!std::isnan(ct), (std::string(who) + ": the classification threshold is NaN").c_str());
}

Result<void, LearnError> validate_restored(std::span<const RestoredCategory> categories,
                                           std::size_t length, bool histograms) noexcept {
  for (std::size_t k = 0; k < categories.size(); ++k) {
    const RestoredCategory& c = categories[k];
    if (auto r = validate_label(c.label); !r) { return r; }
    const bool has_model = !c.accumulators.empty();
    if (!has_model || !c.views.values.empty()) {
      if (auto r = validate_batch(c.views, length, histograms); !r) { return r; }
    }
    if (has_model && c.accumulators.size() != length) { return err(LearnError::WRONG_LENGTH); }
    for (std::size_t j = 0; j < k; ++j) {
      if (categories[j].id == c.id || categories[j].label == c.label) {
        return err(LearnError::DUPLICATE_ID);
      }
    }
  }
  return {};
}

}  // namespace orthoflow::learning
