#include "kernels/descriptor_spec.hpp"

#include <cmath>
#include <cstdio>

namespace orthoflow::kernels {

std::string_view to_string(DescriptorKind kind) noexcept {
  switch (kind) {
    case DescriptorKind::GOOD:
      return "good";
  }
  return "unknown";
}

DescriptorSpec DescriptorSpec::make_good(std::size_t bins, GoodMode mode) noexcept {
  DescriptorSpec s;
  s.good.bins = bins;
  s.good.mode = mode;
  return s;
}

std::size_t DescriptorSpec::length() const noexcept { return 3 * good.bins * good.bins; }

bool DescriptorSpec::histogram() const noexcept { return true; }

Result<void, std::string> DescriptorSpec::validate() const {
  if (good.bins == 0 || good.bins > GOOD_MAX_BINS) {
    return err("descriptor " + describe() + ": bins must be 1.." + std::to_string(GOOD_MAX_BINS));
  }
  const float t = good.effective_threshold();
  if (!std::isfinite(t) || t < 0.0F)
    return err("descriptor " + describe() + ": the threshold must be finite and >= 0");
  return {};
}

std::string DescriptorSpec::describe() const {
  char threshold[32];
  std::snprintf(threshold, sizeof threshold, "%g", static_cast<double>(good.effective_threshold()));
  return std::string(to_string(kind)) + " bins=" + std::to_string(good.bins) +
         " mode=" + (good.mode == GoodMode::INVARIANT ? "invariant" : "reference") +
         " threshold=" + threshold;
}

bool DescriptorSpec::operator==(const DescriptorSpec& other) const noexcept {
  return kind == other.kind && good.bins == other.good.bins && good.mode == other.good.mode &&
         good.effective_threshold() == other.good.effective_threshold();
}

Describer::Describer(const DescriptorSpec& spec) : spec_(spec), good_scratch_(spec.good.bins) {}

Result<DescriptorInfo, GoodError> Describer::describe(PointsView points,
                                                      std::span<float> out) noexcept {
  auto good = compute_good(points, spec_.good, good_scratch_, out);
  if (!good) return err(good.error());
  return DescriptorInfo{good->length, good->frame, good->bbox, good->flags};
}

}  // namespace orthoflow::kernels
