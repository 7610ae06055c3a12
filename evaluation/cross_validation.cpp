#include "evaluation/cross_validation.hpp"

#include "core/rng.hpp"
#include "evaluation/detail/shuffle.hpp"

namespace orthoflow::evaluation {
Result<Folds, EvalError> make_folds(const Dataset& dataset, std::size_t k, std::uint64_t seed) {
  if (k < 2) {
    return err(EvalError{EvalError::Code::BAD_CONFIG,
                         "cross-validation needs at least 2 folds, got " + std::to_string(k)});
  }
  Folds folds{k, std::vector<std::uint32_t>(dataset.views.size(), 0)};
  std::size_t start = 0;
  for (std::uint32_t c = 0; c < dataset.categories.size(); ++c) {
    std::vector<std::size_t> views = dataset.views_of(c);
    if (views.size() < 2) {
      return err(
          EvalError{EvalError::Code::TOO_FEW_VIEWS, "category '" + dataset.categories[c] +
                                                        "' has " + std::to_string(views.size()) +
                                                        " view; cross-validation needs 2 or more"});
    }
    core::Rng rng(seed * 0x9E3779B97F4A7C15ULL + c + 1);
    detail::shuffle(views, rng);
    // Continue dealing where the previous category stopped, so small categories do not all land in
    // fold 0.
    for (std::size_t i = 0; i < views.size(); ++i) {
      folds.fold_of_view[views[i]] = static_cast<std::uint32_t>((start + i) % k);
    }
    start = (start + views.size()) % k;
  }
  return folds;
}

CvResult cross_validate(const Dataset& dataset, const Folds& folds, const DescriptorTable& train,
                        const DescriptorTable& test, const Variant& variant) {
  CvResult result{Confusion(dataset.categories.size()), {}, {}};
  std::vector<float> batch;
  for (std::uint32_t f = 0; f < folds.count; ++f) {
    ClassLearner learner(variant, dataset.categories);
    for (std::uint32_t c = 0; c < dataset.categories.size(); ++c) {
      batch.clear();
      for (const std::size_t v : dataset.views_of(c)) {
        if (folds.fold_of_view[v] != f) {
          batch.insert(batch.end(), train.row(v).begin(), train.row(v).end());
        }
      }
      if (!batch.empty()) { learner.teach(c, batch); }
    }
    Confusion fold(dataset.categories.size());
    for (std::size_t v = 0; v < dataset.views.size(); ++v) {
      if (folds.fold_of_view[v] == f) {
        fold.add(dataset.views[v].category, learner.ask(test.row(v)));
      }
    }
    if (fold.total() > 0) { result.fold_accuracy.push_back(score(fold).accuracy); }
    result.confusion.merge(fold);
  }
  result.scores = score(result.confusion);
  return result;
}

}  // namespace orthoflow::evaluation
