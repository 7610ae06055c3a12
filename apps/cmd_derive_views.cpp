// `orthoflow derive-views FILE... --out DIR [--views V] [--seed S]`: several partial views of each
// single object view (evaluation/derived_views.hpp), laid out as the dataset evaluate reads:
// DIR/<file stem>/<stem>_0/view_NNN.pcd. Every input is checked before anything is written: two
// inputs with one stem would write one category over the other, and an input without a finite
// point would give empty views.
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <map>
#include <memory>
#include <string>
#include <system_error>
#include <vector>

#include "apps/commands.hpp"
#include "evaluation/derived_views.hpp"
#include "formats/pcd_io.hpp"
#include "kernels/cloud_stats.hpp"

namespace orthoflow::apps {
namespace {

struct DeriveOptions {
  std::vector<std::string> files;
  std::string out;
  std::uint32_t views = 10;
  std::uint64_t seed = 1;
};

[[noreturn]] void fail(const std::string& message, int code) {
  std::cerr << "orthoflow derive-views: " << message << '\n';
  throw CLI::RuntimeError(code);
}

/// Two inputs with one stem are one category written twice: refused, naming both.
void check_stems(const std::vector<std::string>& files) {
  std::map<std::string, std::string> first_of_stem;
  for (const std::string& file : files) {
    const std::string stem = std::filesystem::path(file).stem().string();
    const auto [it, fresh] = first_of_stem.emplace(stem, file);
    if (!fresh) {
      fail(it->second + " and " + file + " have the same stem '" + stem +
               "' (the stem names the category): rename one",
           EXIT_USAGE);
    }
  }
}

/// Every input, read and checked: readable, and at least one finite point.
std::vector<kernels::PointCloud> read_inputs(const std::vector<std::string>& files) {
  std::vector<kernels::PointCloud> clouds;
  for (const std::string& file : files) {
    auto cloud = formats::read_pcd(file);
    if (!cloud) fail(cloud.error().to_string(), EXIT_BAD_INPUT);
    if (kernels::cloud_stats(cloud->view().points).finite == 0) {
      fail(file + ": no finite points (" + std::to_string(cloud->size()) +
               " points, all NaN or infinite): no view to derive",
           EXIT_BAD_INPUT);
    }
    clouds.push_back(std::move(*cloud));
  }
  return clouds;
}

void run_derive(const DeriveOptions& o) {
  if (o.out.empty()) fail("--out is an empty path", EXIT_USAGE);
  check_stems(o.files);
  const std::vector<kernels::PointCloud> clouds = read_inputs(o.files);
  for (std::size_t f = 0; f < clouds.size(); ++f) {
    const std::string stem = std::filesystem::path(o.files[f]).stem().string();
    const std::filesystem::path dir = std::filesystem::path(o.out) / stem / (stem + "_0");
    std::error_code ec;
    std::filesystem::create_directories(dir, ec);
    if (ec) fail("cannot create " + dir.string() + ": " + ec.message(), EXIT_FAILURE_GENERIC);
    for (std::uint32_t v = 0; v < o.views; ++v) {
      char name[32];
      std::snprintf(name, sizeof name, "view_%03u.pcd", v);
      auto written = formats::write_pcd(evaluation::derive_view(clouds[f], v, o.seed), dir / name,
                                        formats::PcdEncoding::BINARY);
      if (!written) fail(written.error().to_string(), EXIT_FAILURE_GENERIC);
    }
    std::cout << dir.string() << ": " << o.views << " views\n";
  }
}

}  // namespace

void add_derive_views_command(CLI::App& app) {
  auto o = std::make_shared<DeriveOptions>();
  CLI::App* cmd = app.add_subcommand(
      "derive-views",
      "Lay single views out as DIR/<file stem>/<stem>_0/view_NNN.pcd with random partial crops");
  cmd->add_option("files", o->files,
                  "object view PCD files (one category each, named by the file stem: stems must "
                  "differ; each needs a finite point)")
      ->required();
  cmd->add_option("--out", o->out, "output dataset directory")->required();
  cmd->add_option("--views", o->views, "views per file (view 0 is the file itself)")
      ->check(CLI::Range(1, 10000));
  cmd->add_option("--seed", o->seed, "seed of the crops and noise");
  cmd->callback([o] { run_derive(*o); });
}

}  // namespace orthoflow::apps
