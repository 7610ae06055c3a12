#include "kernels/descriptor_spec.hpp"

#include <cmath>
#include <cstdio>
#include <new>

namespace orthoflow::kernels {

std::string_view to_string(DescriptorKind kind) noexcept {
  switch (kind) {
    case DescriptorKind::GOOD:
      return "good";
    case DescriptorKind::BOW:
      return "bow";
  }
  return "unknown";
}

DescriptorSpec DescriptorSpec::make_good(std::size_t bins, GoodMode mode) noexcept {
  DescriptorSpec s;
  s.good.bins = bins;
  s.good.mode = mode;
  return s;
}

DescriptorSpec DescriptorSpec::make_bow(
    std::shared_ptr<const VisualDictionary> dictionary) noexcept {
  DescriptorSpec s;
  s.kind = DescriptorKind::BOW;
  s.dictionary = std::move(dictionary);
  return s;
}

std::size_t DescriptorSpec::length() const noexcept {
  if (kind == DescriptorKind::BOW) return dictionary ? dictionary->words : 0;
  return 3 * good.bins * good.bins;
}

bool DescriptorSpec::histogram() const noexcept { return true; }

Result<void, std::string> DescriptorSpec::validate() const {
  if (good.bins == 0 || good.bins > GOOD_MAX_BINS) {
    return err("descriptor " + describe() + ": bins must be 1.." + std::to_string(GOOD_MAX_BINS));
  }
  const float t = good.effective_threshold();
  if (!std::isfinite(t) || t < 0.0F)
    return err("descriptor " + describe() + ": the threshold must be finite and >= 0");
  if (kind == DescriptorKind::BOW) {
    if (!dictionary) return err(std::string("descriptor bow: no dictionary"));
    const VisualDictionary& d = *dictionary;
    const std::uint32_t w = d.spin.image_width;
    if (w == 0 || w > MAX_SPIN_IMAGE_WIDTH || d.dims != spin_image_bins(w))
      return err("descriptor " + describe() + ": words of " + std::to_string(d.dims) +
                 " values do not fit spin images of width " + std::to_string(w));
    if (d.words == 0 || d.data.size() != d.words * d.dims)
      return err("descriptor " + describe() + ": the dictionary holds " +
                 std::to_string(d.data.size()) + " values, not words x dims");
    const auto positive = [](float v) { return std::isfinite(v) && v > 0.0F; };
    if (!positive(d.spin.support_length) || !positive(d.keypoint_leaf) ||
        !positive(d.normal_radius) || !(d.spin.support_angle_cos >= 0.0F) ||
        d.spin.support_angle_cos > 1.0F)
      return err("descriptor " + describe() +
                 ": support length, keypoint leaf and normal radius must be finite and > 0, the "
                 "support angle's cosine in [0, 1]");
  }
  return {};
}

std::string DescriptorSpec::describe() const {
  char text[160];
  if (kind == DescriptorKind::BOW) {
    if (!dictionary) return "bow (no dictionary)";
    const VisualDictionary& d = *dictionary;
    std::snprintf(text, sizeof text, "bow words=%zu iw=%u sl=%g vs=%g nr=%g dictionary=%s", d.words,
                  d.spin.image_width, static_cast<double>(d.spin.support_length),
                  static_cast<double>(d.keypoint_leaf), static_cast<double>(d.normal_radius),
                  dictionary_id_hex(d.id).c_str());
    return text;
  }
  std::snprintf(text, sizeof text, "%g", static_cast<double>(good.effective_threshold()));
  return std::string(to_string(kind)) + " bins=" + std::to_string(good.bins) +
         " mode=" + (good.mode == GoodMode::INVARIANT ? "invariant" : "reference") +
         " threshold=" + text;
}

bool DescriptorSpec::operator==(const DescriptorSpec& other) const noexcept {
  const bool same_good = good.bins == other.good.bins && good.mode == other.good.mode &&
                         good.effective_threshold() == other.good.effective_threshold();
  if (kind != other.kind || !same_good) return false;
  if (kind == DescriptorKind::BOW) {
    if (!dictionary || !other.dictionary) return dictionary == other.dictionary;
    return dictionary->id == other.dictionary->id && dictionary->words == other.dictionary->words;
  }
  return true;
}

Describer::Describer(const DescriptorSpec& spec) : spec_(spec), good_scratch_(spec.good.bins) {
  if (spec_.kind == DescriptorKind::BOW && spec_.dictionary) {
    good_values_.resize(3 * spec_.good.bins * spec_.good.bins);
    word_scratch_.resize(spec_.dictionary->words);
  }
}

Result<void, GoodError> Describer::describe_bow(PointsView points, std::span<float> out,
                                                SpinFeatures& features) {
  const VisualDictionary& d = *spec_.dictionary;
  const SpinFeatureParams params{d.spin, d.keypoint_leaf, d.normal_radius};
  auto computed = features.compute(points, params);
  if (!computed) {
    switch (computed.error()) {
      case SpinFeatureError::OUT_OF_MEMORY:
        return err(GoodError::OUT_OF_MEMORY);
      case SpinFeatureError::TOO_MANY_POINTS:
        return err(GoodError::TOO_MANY_POINTS);
      default:
        return err(GoodError::KEYPOINTS_FAILED);
    }
  }
  features_ = bag_of_words(features.images(), d.view(), word_scratch_, out);
  if (features_ == 0) return err(GoodError::NO_FEATURES);
  return {};
}

Result<DescriptorInfo, GoodError> Describer::describe(PointsView points,
                                                      std::span<float> out) noexcept {
  return describe(points, out, features_scratch_);
}

Result<DescriptorInfo, GoodError> Describer::describe(PointsView points, std::span<float> out,
                                                      SpinFeatures& features) noexcept {
  features_ = 0;
  if (spec_.kind == DescriptorKind::GOOD) {
    auto good = compute_good(points, spec_.good, good_scratch_, out);
    if (!good) return err(good.error());
    return DescriptorInfo{good->length, good->frame, good->bbox, good->flags};
  }
  if (!spec_.dictionary || out.size() < spec_.length()) return err(GoodError::OUTPUT_TOO_SMALL);
  // The frame and box come from GOOD (the grasp planner needs them whatever the representation).
  auto good = compute_good(points, spec_.good, good_scratch_, good_values_);
  if (!good) return err(good.error());
  auto bow = describe_bow(points, out, features);
  if (!bow) return err(bow.error());
  return DescriptorInfo{spec_.length(), good->frame, good->bbox, good->flags};
}

}  // namespace orthoflow::kernels
