// The learning section of the golden file: GOOD descriptors of rendered object views, a fixed
// teach/ask sequence on both learners, and every decision (label, unknown flag, scores).
#include <array>
#include <cmath>
#include <cstdint>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include "golden_outputs.hpp"
#include "kernels/good.hpp"
#include "learning/bayes_learner.hpp"
#include "learning/instance_learner.hpp"
#include "simulation/world/object_catalog.hpp"
#include "simulation/world/object_dataset.hpp"

namespace orthoflow::testing {
namespace {

namespace osim = orthoflow::simulation;
namespace ok = orthoflow::kernels;
namespace ol = orthoflow::learning;

constexpr std::array<osim::Category, 4> CATEGORIES{osim::Category::MUG, osim::Category::BOTTLE,
                                                   osim::Category::BOWL, osim::Category::KNIFE};
constexpr std::uint32_t INSTANCES = 2;
constexpr std::uint32_t TAUGHT_VIEWS =
    2;  // views 0..1 of each instance are taught, view 2 is asked

std::vector<float> descriptor_of_view(osim::Category cat, std::uint32_t instance, std::uint32_t v) {
  osim::DatasetConfig config;
  config.seed = 5;
  config.render.intrinsics =
      osim::DepthIntrinsics{287.9, 287.9, 159.5, 119.5, 320, 240};  // half resolution
  const osim::ObjectModel model = osim::make_object_model(cat, instance, config.seed);
  ok::PointCloud frame, view;
  core::Rng noise(1000U * static_cast<std::uint32_t>(cat) + 10U * instance + v);
  osim::render_object_view(model, osim::dataset_view(config, cat, instance, v), config.render,
                           noise, frame, view);
  ok::GoodConfig cfg;
  ok::GoodScratch scratch(cfg.bins);
  std::vector<float> d(3 * cfg.bins * cfg.bins);
  auto good_result = ok::compute_good(view.points(), cfg, scratch, d);
  if (!good_result) {
    throw std::runtime_error(std::string("GOOD of a ") + osim::category_name(cat) +
                             " view: " + ok::to_string(good_result.error()));
  }
  return d;
}

// A score that is not finite (no runner-up yet) is stored as null.
nlohmann::json score(float v) {
  return std::isfinite(v) ? nlohmann::json(static_cast<double>(v)) : nlohmann::json();
}

nlohmann::json decision(const ol::Prediction& p) {
  return {{"label", std::string(p.label.view())},
          {"unknown", p.unknown},
          {"score", score(p.score)},
          {"runner_up", std::string(p.runner_up.view())},
          {"runner_up_score", score(p.runner_up_score)}};
}

}  // namespace

nlohmann::json golden_learning() {
  // Held-out views to ask: view TAUGHT_VIEWS of every instance, in a fixed order.
  std::vector<std::vector<float>> asked;
  for (osim::Category cat : CATEGORIES) {
    for (std::uint32_t i = 0; i < INSTANCES; ++i) {
      asked.push_back(descriptor_of_view(cat, i, TAUGHT_VIEWS));
    }
  }
  std::vector<std::unique_ptr<ol::Learner>> learners;
  learners.push_back(std::make_unique<ol::InstanceLearner>(ol::InstanceConfig{}));
  learners.push_back(std::make_unique<ol::BayesLearner>(ol::BayesConfig{}));
  nlohmann::json out = nlohmann::json::object();
  ol::AskScratch scratch;
  for (auto& learner : learners) {
    nlohmann::json steps = nlohmann::json::array();
    for (osim::Category cat :
         CATEGORIES) {  // open-ended: one new category per step, then ask everything
      for (std::uint32_t i = 0; i < INSTANCES; ++i) {
        std::vector<float> batch;
        for (std::uint32_t v = 0; v < TAUGHT_VIEWS; ++v) {
          const std::vector<float> d = descriptor_of_view(cat, i, v);
          batch.insert(batch.end(), d.begin(), d.end());
        }
        auto taught = learner->teach(osim::category_name(cat),
                                     ol::DescriptorBatch{batch, asked.front().size()});
        if (!taught) {
          throw std::runtime_error(std::string("teach: ") + ol::to_string(taught.error()));
        }
      }
      nlohmann::json answers = nlohmann::json::array();
      for (const auto& d : asked) { answers.push_back(decision(learner->ask(d, scratch))); }
      steps.push_back({{"taught", osim::category_name(cat)}, {"answers", std::move(answers)}});
    }
    out[learner->kind()] = std::move(steps);
  }
  return out;
}

}  // namespace orthoflow::testing
