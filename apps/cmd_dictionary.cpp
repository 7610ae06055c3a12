// `orthoflow dictionary build --from DIR... | --scenes DIR... [--graph FILE|tabletop] --out FILE
// [--words 70] [--image-width 4]
// [--support-length 0.05] [--keypoint-leaf 0.01] [--normal-radius 0.02] [--seed 1]
// [--iterations 100] [--topics K [--alpha 1] [--beta 0.1] [--gibbs-iterations 30]] [--threads N]`
// and `orthoflow dictionary show FILE [--json]`: the dictionary
// of visual words of the bag-of-words representation (learning/dictionary.hpp,
// docs/SPIN_IMAGES.md). `build` is the thesis's exploration stage: every object view (*.pcd) under
// the --from directories, labelled or not, and every object the product's segmentation finds in the
// frames under --scenes (chapter 3's unsupervised object discovery: what the robot sees before
// anyone teaches it), is described by its spin images at its keypoints, and k-means makes the pool
// into words. The same files, parameters and seed give the same file, whatever the threads.
// This file holds the options, build and show; the inputs build describes are gathered in
// cmd_dictionary_inputs.cpp (apps/dictionary_cli.hpp).
#include <tbb/enumerable_thread_specific.h>
#include <tbb/global_control.h>
#include <tbb/parallel_for.h>

#include <filesystem>
#include <iostream>
#include <memory>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "apps/commands.hpp"
#include "apps/dictionary_cli.hpp"
#include "formats/pcd_io.hpp"
#include "kernels/spin_features.hpp"
#include "learning/dictionary.hpp"
#include "learning/topic_training.hpp"

namespace orthoflow::apps {

namespace dictionary_cli {

[[noreturn]] void fail(const std::string& message, int code) {
  std::cerr << "orthoflow dictionary: " << message << '\n';
  throw CLI::RuntimeError(code);
}

}  // namespace dictionary_cli

namespace {

using namespace dictionary_cli;

struct DictionaryOptions {
  std::vector<std::string> from;
  std::vector<std::string> scenes;
  std::string graph = "tabletop";
  std::string out;
  std::size_t words = 70;
  std::uint32_t image_width = 4;
  float support_length = 0.05F;
  float keypoint_leaf = 0.01F;
  float normal_radius = 0.02F;
  std::uint64_t seed = 1;
  std::uint32_t iterations = 100;
  std::size_t topics = 0;  // 0: no topic model
  double alpha = 1.0, beta = 0.1;
  std::uint32_t gibbs = 30;
  std::size_t threads = 0;
  std::string file;
  bool json = false;
};

void run_build(const DictionaryOptions& o) {
  if (o.from.empty() && o.scenes.empty()) fail("build needs --from or --scenes", EXIT_USAGE);
  const auto files = o.from.empty() ? std::vector<std::filesystem::path>{} : views_under(o.from);
  if (!o.from.empty() && files.empty())
    fail("no *.pcd object view under the given directories", EXIT_BAD_INPUT);
  std::size_t frames = 0;
  const std::vector<kernels::PointCloud> found = o.scenes.empty()
                                                     ? std::vector<kernels::PointCloud>{}
                                                     : objects_in_scenes(o.scenes, o.graph, frames);
  if (!o.scenes.empty() && found.empty())
    fail("the segmentation found no object in the --scenes frames", EXIT_BAD_INPUT);
  kernels::SpinFeatureParams params;
  params.spin.image_width = o.image_width;
  params.spin.support_length = o.support_length;
  params.keypoint_leaf = o.keypoint_leaf;
  params.normal_radius = o.normal_radius;
  std::optional<tbb::global_control> threads;
  if (o.threads > 0) threads.emplace(tbb::global_control::max_allowed_parallelism, o.threads);
  // Each view's images in its own slot, then joined in file order: the pool does not depend on
  // the threads.
  // The views first, then the objects found in the scenes.
  const std::size_t total = files.size() + found.size();
  std::vector<std::vector<float>> images(total);
  std::vector<std::string> errors(total);
  tbb::enumerable_thread_specific<kernels::SpinFeatures> scratch;
  tbb::parallel_for(std::size_t{0}, total, [&](std::size_t i) {
    std::optional<kernels::PointCloud> read;
    if (i < files.size()) {
      auto cloud = formats::read_pcd(files[i]);
      if (!cloud) {
        errors[i] = files[i].string() + ": " + cloud.error().to_string();
        return;
      }
      read.emplace(std::move(*cloud));
    }
    const kernels::PointCloud& cloud = read ? *read : found[i - files.size()];
    const std::string name =
        i < files.size() ? files[i].string()
                         : "object " + std::to_string(i - files.size()) + " found in the scenes";
    kernels::SpinFeatures& features = scratch.local();
    auto k = features.compute(cloud.points(), params);
    if (!k) {
      errors[i] = name + ": " + kernels::to_string(k.error());
      return;
    }
    images[i].assign(features.images().begin(), features.images().end());
  });
  for (const std::string& e : errors)
    if (!e.empty()) fail(e, EXIT_BAD_INPUT);
  std::vector<float> pool;
  for (const auto& v : images) pool.insert(pool.end(), v.begin(), v.end());
  learning::KMeansParams km;
  km.k = o.words;
  km.seed = o.seed;
  km.max_iterations = o.iterations;
  std::string provenance;
  if (!files.empty()) {
    provenance = std::to_string(files.size()) + " views under";
    for (const std::string& root : o.from) provenance += " " + root;
  }
  if (!found.empty()) {
    if (!provenance.empty()) provenance += "; ";
    provenance += std::to_string(found.size()) + " objects segmented (" + o.graph + ") from " +
                  std::to_string(frames) + " frames under";
    for (const std::string& root : o.scenes) provenance += " " + root;
  }
  auto d = learning::build_dictionary(pool, params, km, provenance);
  if (!d) fail(d.error(), EXIT_USAGE);
  if (o.topics > 0) {  // the topic layer: LDA over the same views' words
    learning::TopicFitParams tp;
    tp.topics = o.topics;
    tp.alpha = o.alpha;
    tp.beta = o.beta;
    tp.iterations = o.gibbs;
    tp.seed = o.seed;
    if (auto fitted = learning::add_topics(*d, images, tp); !fitted)
      fail(fitted.error(), EXIT_USAGE);
    d->provenance += "; LDA of " + std::to_string(o.topics) + " topics over the views' words, " +
                     std::to_string(o.gibbs) + " Gibbs sweeps";
  }
  if (const std::string why = learning::save_dictionary(*d, o.out); !why.empty())
    fail(why, EXIT_FAILURE_GENERIC);
  std::cout << "dictionary " << kernels::dictionary_id_hex(d->id) << ": " << d->words
            << " words of " << d->dims << " values"
            << (d->topics ? ", " + std::to_string(d->topics->topics) + " topics" : std::string())
            << "; " << d->provenance << "\nwrote " << o.out << '\n';
}

void run_show(const DictionaryOptions& o) {
  auto d = learning::load_dictionary(o.file);
  if (!d) fail(d.error(), EXIT_BAD_INPUT);
  if (o.json) {
    const nlohmann::json j{{"id", kernels::dictionary_id_hex(d->id)},
                           {"words", d->words},
                           {"dims", d->dims},
                           {"image_width", d->spin.image_width},
                           {"support_length_m", d->spin.support_length},
                           {"support_angle_cos", d->spin.support_angle_cos},
                           {"keypoint_leaf_m", d->keypoint_leaf},
                           {"normal_radius_m", d->normal_radius},
                           {"topics", d->topics ? d->topics->topics : 0},
                           {"provenance", d->provenance}};
    std::cout << j.dump() << '\n';
    return;
  }
  std::cout << "dictionary " << kernels::dictionary_id_hex(d->id) << "\n  words " << d->words
            << " of " << d->dims << " values\n  spin images: IW " << d->spin.image_width << ", SL "
            << d->spin.support_length << " m, support angle cos " << d->spin.support_angle_cos
            << "\n  keypoints: VS " << d->keypoint_leaf << " m; normals: radius "
            << d->normal_radius << " m\n  provenance: " << d->provenance << '\n';
}

}  // namespace

void add_dictionary_command(CLI::App& app) {
  auto o = std::make_shared<DictionaryOptions>();
  CLI::App* cmd = app.add_subcommand(
      "dictionary", "the visual words of the bag-of-words representation (docs/SPIN_IMAGES.md)");
  cmd->require_subcommand(1);
  CLI::App* build = cmd->add_subcommand(
      "build",
      "k-means over the spin images of every object view (*.pcd) under --from DIR... and of "
      "every object segmented from the frames under --scenes DIR...");
  build->add_option("--from", o->from, "directories (or files) of object views");
  build->add_option("--scenes", o->scenes,
                    "directories (or files) of camera frames: the objects the segmentation finds "
                    "in them (the exploration of thesis chapter 3)");
  build->add_option("--graph", o->graph,
                    "--scenes: the segmentation of this graph file ('tabletop': the embedded one)");
  build->add_option("--out", o->out, "the dictionary file to write")->required();
  build->add_option("--words", o->words, "dictionary size DS (thesis: 70)")
      ->check(CLI::Range(1, 65536));
  build->add_option("--image-width", o->image_width, "spin image width IW (thesis: 4)")
      ->check(CLI::Range(1, 16));
  build->add_option("--support-length", o->support_length, "spin image support SL, m (0.05)")
      ->check(CLI::Range(0.001, 1.0));
  build->add_option("--keypoint-leaf", o->keypoint_leaf, "keypoints' voxel size VS, m (0.01)")
      ->check(CLI::Range(0.001, 1.0));
  build->add_option("--normal-radius", o->normal_radius, "normals' radius, m (0.02)")
      ->check(CLI::Range(0.001, 1.0));
  build->add_option("--seed", o->seed, "k-means++ seed");
  build->add_option("--iterations", o->iterations, "k-means iterations at most")
      ->check(CLI::Range(1, 100000));
  build
      ->add_option("--topics", o->topics,
                   "also fit LDA with this many topics over the views' words (0: none; thesis: 30)")
      ->check(CLI::Range(0, 1024));
  build->add_option("--alpha", o->alpha, "LDA's Dirichlet prior on topics (1.0)")
      ->check(CLI::Range(1e-6, 1e6));
  build->add_option("--beta", o->beta, "LDA's Dirichlet prior on words (0.1)")
      ->check(CLI::Range(1e-6, 1e6));
  build->add_option("--gibbs-iterations", o->gibbs, "Gibbs sweeps, fitting and inference (30)")
      ->check(CLI::Range(1, 10000));
  build->add_option("--threads", o->threads,
                    "worker threads (0: all); the words do not depend on it");
  build->callback([o] { run_build(*o); });
  CLI::App* show = cmd->add_subcommand("show", "a dictionary's words, parameters and provenance");
  show->add_option("file", o->file, "dictionary file")->required();
  show->add_flag("--json", o->json, "one JSON object");
  show->callback([o] { run_show(*o); });
}

}  // namespace orthoflow::apps
