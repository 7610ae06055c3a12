// One segmentation chain, and the product runs it (issue: the house): on every frame of
// ../shared/data/scenes, ../shared/data/mosd_learn and a few synthetic scenes, `orthoflow segment
// --graph tabletop --json FILE` and the objects of `orthoflow run --source pcd:DIR --json-out`
// agree: the same object count, and centroids and point counts of the objects in the same order
// within 1 mm.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "tests/support/command_output.hpp"

namespace {

namespace fs = std::filesystem;

using orthoflow::test::pcd_files;
using Output = orthoflow::test::CommandOutput;

Output run(const std::string& command) {
  return orthoflow::test::run_command(command + " 2>/dev/null");
}

/// `orthoflow segment --graph tabletop --json` on @p file against the objects of @p frame.
void expect_same_objects(const fs::path& file, const nlohmann::json& frame) {
  const Output seg =
      run(std::string(ORTHOFLOW_CLI) + " segment --graph tabletop --json " + file.string());
  if (seg.status != 0) {  // no table: the graph must have found none either, and no object
    EXPECT_FALSE(frame["table"].get<bool>());
    EXPECT_TRUE(frame["objects"].empty());
    return;
  }
  const auto ours = nlohmann::json::parse(seg.text);
  const auto& want = ours["objects"];
  const auto& got = frame["objects"];
  EXPECT_TRUE(frame["table"].get<bool>());
  ASSERT_EQ(got.size(), want.size());
  for (std::size_t k = 0; k < got.size(); ++k) {
    EXPECT_EQ(got[k]["points"].get<std::size_t>(), want[k]["points"].get<std::size_t>())
        << "object " << k;
    for (std::size_t a = 0; a < 3; ++a) {
      EXPECT_NEAR(got[k]["centroid"][a].get<double>(), want[k]["centroid"][a].get<double>(), 1e-3)
          << "object " << k << " axis " << a;
    }
  }
}

/// Runs both commands on every frame of @p dir and compares them; returns the frames compared.
std::size_t expect_agreement(const fs::path& dir) {
  const std::string cli = ORTHOFLOW_CLI;
  const fs::path lines =
      fs::path(ORTHOFLOW_BINARY_DIR) / ("equivalence_" + dir.filename().string() + ".jsonl");
  const Output ran = run(cli + " run --source pcd:" + dir.string() +
                         " --rate max --threads 1 --json-out " + lines.string());
  EXPECT_EQ(ran.status, 0) << ran.text;
  std::ifstream in(lines);
  std::vector<nlohmann::json> frames;
  for (std::string line; std::getline(in, line);) frames.push_back(nlohmann::json::parse(line));
  const auto files = pcd_files(dir);
  EXPECT_EQ(frames.size(), files.size()) << dir;
  std::size_t compared = 0;
  for (std::size_t f = 0; f < std::min(frames.size(), files.size()); ++f) {
    SCOPED_TRACE(files[f].string());
    EXPECT_EQ(frames[f]["frame"].get<std::size_t>(), f);
    expect_same_objects(files[f], frames[f]);
    ++compared;
  }
  return compared;
}

TEST(SegmentRunEquivalence, SharedScenes) {
  EXPECT_EQ(expect_agreement(fs::path(ORTHOFLOW_SHARED_DIR) / "data/scenes"), 3U);
}

TEST(SegmentRunEquivalence, MosdLearnSplit) {
  EXPECT_EQ(expect_agreement(fs::path(ORTHOFLOW_SHARED_DIR) / "data/mosd_learn"), 45U);
}

TEST(SegmentRunEquivalence, SyntheticScenesTouchingAndApart) {
  const fs::path dir = fs::path(ORTHOFLOW_BINARY_DIR) / "equivalence_synthetic";
  fs::remove_all(dir);
  fs::create_directories(dir);
  const std::string cli = ORTHOFLOW_CLI;
  for (int seed = 1; seed <= 4; ++seed) {
    const std::string touching = seed % 2 == 0 ? " --touching" : "";
    const auto made = run(cli + " synth --objects " + std::to_string(2 + seed) + " --seed " +
                          std::to_string(seed) + touching + " --out " +
                          (dir / ("scene" + std::to_string(seed) + ".pcd")).string());
    ASSERT_EQ(made.status, 0) << made.text;
  }
  EXPECT_EQ(expect_agreement(dir), 4U);
}

}  // namespace
