#pragma once
/// @file
/// @brief The simulated teacher (thesis section 7.1, Algorithm 7.1) and its context-change variant
/// (section 7.3, Algorithm 7.2), on precomputed descriptors.
///
/// Rules as implemented (docs/EVALUATION.md states them with the reasons):
/// - A category is introduced by teaching `intro_views` (3) views picked at random from its views.
/// - A question/correction iteration shows a previously unseen view of known category c (c cycles
/// over the
///   known categories in introduction order), asks, and teaches it back (correct) when the answer
///   is wrong.
/// - The protocol accuracy s is the accuracy of the last k answers, k counting iterations since the
/// last
///   introduction and capped at 3n (n = categories introduced). When s > tau and k >= n, the newest
///   category counts as learned and the next one is introduced.
/// - Breakpoint: `breakpoint` iterations since the last introduction without reaching that
/// condition.
/// - Lack of data: no category left to introduce, or the category to ask has no unseen view left.
/// - Context change: the first `context_a` categories of the order form context A, the rest context
/// B;
///   once all of A is learned the teacher introduces B's categories and asks only about B's
///   (questions about the other context are skipped, not counted).
#include <cstdint>
#include <span>
#include <vector>

#include "evaluation/dataset.hpp"
#include "evaluation/descriptors.hpp"
#include "evaluation/variant.hpp"

namespace orthoflow::evaluation {

struct TeacherConfig {
  double tau = 0.67;             ///< protocol accuracy threshold
  std::size_t breakpoint = 100;  ///< iterations without reaching tau before the teacher gives up
  std::size_t intro_views = 3;   ///< views taught when a category is introduced
  std::size_t context_a =
      0;  ///< 0: no context change (Algorithm 7.1); else size of context A (7.2)
};

enum class TeacherStop : std::uint8_t { BREAKPOINT, LACK_OF_DATA };
[[nodiscard]] const char* to_string(TeacherStop stop) noexcept;

/// @brief The state when a category was learned (for the plots).
struct LearnedPoint {
  std::size_t iteration = 0;  ///< question/correction iterations so far
  std::size_t learned = 0;    ///< categories learned so far (this one included)
  double gca = 0.0;           ///< global classification accuracy so far
};

/// @brief Metrics of one experiment (thesis 7.1.2).
struct TeacherRun {
  std::size_t nlc = 0;  ///< number of learned categories
  std::size_t qci = 0;  ///< question/correction iterations
  double aic = 0.0;     ///< average stored instances (views) per category at the end
  double gca = 0.0;     ///< correct answers / all answers
  double apa = 0.0;     ///< mean of the protocol accuracy over all iterations
  TeacherStop stop = TeacherStop::LACK_OF_DATA;
  std::size_t learned_a = 0;  ///< context change: categories learned in context A
  std::size_t learned_b = 0;  ///< context change: categories learned in context B
  bool switched = false;      ///< context change: context B was reached
  std::vector<LearnedPoint> curve;
};

/// @brief Runs one experiment of @p variant: categories introduced in @p order (dataset category
/// indices); each category's views are shuffled by a generator seeded with (@p view_seed,
/// category), so two variants given the same order and seed see the same views in the same order.
/// @pre descriptors has one row per dataset view; order holds distinct valid categories.
/// @note Deterministic; single-threaded.
[[nodiscard]] TeacherRun run_teacher(const Dataset& dataset, const DescriptorTable& descriptors,
                                     const Variant& variant, std::span<const std::uint32_t> order,
                                     const TeacherConfig& config, std::uint64_t view_seed);

/// @brief A random order of @p categories categories from @p seed (portable Fisher-Yates).
[[nodiscard]] std::vector<std::uint32_t> category_order(std::size_t categories, std::uint64_t seed);

}  // namespace orthoflow::evaluation
