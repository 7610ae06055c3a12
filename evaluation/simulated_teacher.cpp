#include "evaluation/simulated_teacher.hpp"

#include <algorithm>
#include <deque>

#include "core/rng.hpp"
#include "evaluation/detail/shuffle.hpp"

namespace orthoflow::evaluation {
namespace {

/// The teacher's bookkeeping for one experiment.
class Teacher {
 public:
  Teacher(const Dataset& ds, const DescriptorTable& d, const Variant& v,
          std::span<const std::uint32_t> order, const TeacherConfig& cfg, std::uint64_t seed)
      : ds_(ds),
        d_(d),
        order_(order),
        cfg_(cfg),
        learner_(v, ds.categories),
        unseen_(ds.categories.size()) {
    for (std::uint32_t c = 0; c < ds.categories.size(); ++c) {
      std::vector<std::size_t> views = ds.views_of(c);
      core::Rng rng(seed * 0xD1B54A32D192ED03ULL + c + 1);
      detail::shuffle(views, rng);
      unseen_[c].assign(views.begin(), views.end());
    }
  }

  TeacherRun run() {
    if (!introduce()) { return finish(TeacherStop::LACK_OF_DATA); }
    mark_learned();  // Algorithm 7.1 line 1: the first category is known without questions
    while (true) {
      if (cfg_.context_a > 0 && !in_b_ && learned_ == cfg_.context_a) {
        in_b_ = true;
        run_.switched = true;
      }
      if (!introduce()) { return finish(TeacherStop::LACK_OF_DATA); }
      const auto outcome = question_round();
      if (outcome) { return finish(*outcome); }
      mark_learned();
    }
  }

 private:
  bool in_context(std::size_t position) const {
    return cfg_.context_a == 0 || (position < cfg_.context_a) != in_b_;
  }

  /// Teaches the next category of the order with intro_views unseen views; false when none is left.
  bool introduce() {
    if (introduced_ == order_.size()) { return false; }
    const std::uint32_t c = order_[introduced_];
    if (unseen_[c].size() < cfg_.intro_views) { return false; }
    std::vector<float> batch;
    for (std::size_t i = 0; i < cfg_.intro_views; ++i) { take(c, batch); }
    learner_.teach(c, batch);
    stored_ += cfg_.intro_views;
    ++introduced_;
    return true;
  }

  void take(std::uint32_t c, std::vector<float>& out) {
    const auto row = d_.row(unseen_[c].front());
    unseen_[c].pop_front();
    out.insert(out.end(), row.begin(), row.end());
  }

  /// Question/correction iterations until the newest category is learned; the stop reason
  /// otherwise.
  std::optional<TeacherStop> question_round() {
    window_.clear();
    const std::size_t n = introduced_;
    std::size_t c = 0, k = 0, since = 0;
    std::vector<float> view;
    while (true) {
      const std::size_t position = c;
      c = c + 1 < n ? c + 1 : 0;
      if (!in_context(position)) { continue; }
      const std::uint32_t cls = order_[position];
      if (unseen_[cls].empty()) { return TeacherStop::LACK_OF_DATA; }
      view.clear();
      take(cls, view);
      const auto answer = learner_.ask(view);
      const bool right = answer && *answer == cls;
      if (!right) {
        learner_.teach(cls, view);
        ++stored_;
      }
      record(right);
      k = std::min(k + 1, 3 * n);
      const double s = window_accuracy(k);
      accuracy_sum_ += s;
      ++since;
      if (s > cfg_.tau && k >= n) { return std::nullopt; }
      if (since >= cfg_.breakpoint) { return TeacherStop::BREAKPOINT; }
    }
  }

  void record(bool right) {
    ++run_.qci;
    correct_ += right ? 1 : 0;
    window_.push_back(right);
  }

  double window_accuracy(std::size_t k) const {
    std::size_t good = 0;
    for (std::size_t i = window_.size() - k; i < window_.size(); ++i) {
      good += window_[i] ? 1 : 0;
    }
    return static_cast<double>(good) / static_cast<double>(k);
  }

  void mark_learned() {
    ++learned_;
    if (in_b_) {
      ++run_.learned_b;
    } else {
      ++run_.learned_a;
    }
    run_.curve.push_back(LearnedPoint{run_.qci, learned_, gca()});
  }

  double gca() const {
    return run_.qci == 0 ? 0.0 : static_cast<double>(correct_) / static_cast<double>(run_.qci);
  }

  TeacherRun finish(TeacherStop stop) {
    run_.stop = stop;
    run_.nlc = learned_;
    run_.gca = gca();
    run_.apa = run_.qci == 0 ? 0.0 : accuracy_sum_ / static_cast<double>(run_.qci);
    run_.aic =
        introduced_ == 0 ? 0.0 : static_cast<double>(stored_) / static_cast<double>(introduced_);
    if (cfg_.context_a == 0) {
      run_.learned_a = learned_;
      run_.learned_b = 0;
    }
    return run_;
  }

  const Dataset& ds_;
  const DescriptorTable& d_;
  std::span<const std::uint32_t> order_;
  TeacherConfig cfg_;
  ClassLearner learner_;
  std::vector<std::deque<std::size_t>> unseen_;
  std::vector<bool> window_;
  std::size_t introduced_ = 0, learned_ = 0, stored_ = 0, correct_ = 0;
  double accuracy_sum_ = 0.0;
  bool in_b_ = false;
  TeacherRun run_;
};

}  // namespace

const char* to_string(TeacherStop stop) noexcept {
  return stop == TeacherStop::BREAKPOINT ? "breakpoint" : "lack of data";
}

TeacherRun run_teacher(const Dataset& dataset, const DescriptorTable& descriptors,
                       const Variant& variant, std::span<const std::uint32_t> order,
                       const TeacherConfig& config, std::uint64_t view_seed) {
  Teacher teacher(dataset, descriptors, variant, order, config, view_seed);
  return teacher.run();
}

std::vector<std::uint32_t> category_order(std::size_t categories, std::uint64_t seed) {
  std::vector<std::uint32_t> order(categories);
  for (std::uint32_t c = 0; c < categories; ++c) { order[c] = c; }
  core::Rng rng(seed ^ 0xA0761D6478BD642FULL);
  detail::shuffle(order, rng);
  return order;
}

}  // namespace orthoflow::evaluation
