// Segmentation scoring on hand-made label images with known answers (matches, splits, merges,
// the IoU 0.5 boundary, one-to-one matching, plane quality with a known tilt), the frame listing
// and names file, evaluate_segmentation() on frames on disk (an unreadable frame is a failed row,
// never a score), the label picture, and the product's chain as a segmenter on a synthetic frame.
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <nlohmann/json.hpp>

#include "evaluation/segmentation_eval.hpp"
#include "formats/pcd_io.hpp"
#include "kernels/frame_labels.hpp"
#include "simulation/world/synthetic_scene.hpp"
#include "tests/evaluation/box_dataset.hpp"

namespace orthoflow::evaluation {
namespace {

namespace fs = std::filesystem;
using Labels = std::vector<std::uint32_t>;

/// A label image from a run-length description: {label, count} pairs.
Labels runs(std::initializer_list<std::pair<std::uint32_t, std::size_t>> parts) {
  Labels out;
  for (const auto& [label, n] : parts) out.insert(out.end(), n, label);
  return out;
}

TEST(SegmentationScore, PerfectMatchCountsEveryObject) {
  const Labels truth = runs({{1, 50}, {20, 30}, {21, 10}, {30, 40}, {0, 5}});
  const Labels pred = runs({{1, 50}, {2, 40}, {3, 40}, {0, 5}});
  const auto c = score_objects(truth, pred);
  EXPECT_EQ(c.truth, 2U);  // parts 20 and 21 are one object (k = 2)
  EXPECT_EQ(c.predicted, 2U);
  EXPECT_EQ(c.matched, 2U);
  EXPECT_EQ(c.over, 0U);
  EXPECT_EQ(c.under, 0U);
  EXPECT_DOUBLE_EQ(c.precision(), 1.0);
  EXPECT_DOUBLE_EQ(c.recall(), 1.0);
  EXPECT_DOUBLE_EQ(c.matched_iou, 2.0);
}

TEST(SegmentationScore, MergedObjectsAreUnderSegmentation) {
  // One prediction over two equal objects: IoU 0.5 with each, but only one may take it.
  const Labels truth = runs({{20, 50}, {30, 50}});
  const Labels pred = runs({{2, 100}});
  const auto c = score_objects(truth, pred);
  EXPECT_EQ(c.truth, 2U);
  EXPECT_EQ(c.predicted, 1U);
  EXPECT_EQ(c.matched, 1U);  // one-to-one: the second object finds the prediction taken
  EXPECT_EQ(c.under, 1U);
  EXPECT_EQ(c.over, 0U);
  EXPECT_DOUBLE_EQ(c.recall(), 0.5);
}

TEST(SegmentationScore, SplitObjectIsOverSegmentation) {
  // 100 pixels split 60 / 40: the 60 piece has IoU 0.6 (a match), the 40 piece is extra.
  const Labels truth = runs({{40, 100}});
  const Labels pred = runs({{2, 60}, {3, 40}});
  const auto c = score_objects(truth, pred);
  EXPECT_EQ(c.matched, 1U);
  EXPECT_EQ(c.over, 1U);
  EXPECT_DOUBLE_EQ(c.precision(), 0.5);
  // Split in three (45 / 45 / 10): no piece reaches IoU 0.5; the 10 % piece still counts as a part.
  const auto three = score_objects(truth, runs({{2, 45}, {3, 45}, {4, 10}}));
  EXPECT_EQ(three.matched, 0U);
  EXPECT_EQ(three.over, 1U);
}

TEST(SegmentationScore, IouJustBelowHalfIsNoMatch) {
  // Object 100 pixels, prediction 99 of them plus 101 table pixels: IoU 99 / 201 < 0.5.
  const Labels truth = runs({{20, 100}, {1, 101}});
  EXPECT_EQ(score_objects(truth, runs({{2, 201}})).matched, 0U);
  // 100 of them plus 100 table pixels: IoU exactly 0.5 is a match.
  const Labels truth2 = runs({{20, 100}, {1, 100}});
  EXPECT_EQ(score_objects(truth2, runs({{2, 200}})).matched, 1U);
}

TEST(SegmentationScore, PredictionsOnEmptyTruthAreAllWrong) {
  const auto c = score_objects(runs({{1, 10}}), runs({{2, 5}, {1, 5}}));
  EXPECT_EQ(c.truth, 0U);
  EXPECT_EQ(c.predicted, 1U);
  EXPECT_DOUBLE_EQ(c.precision(), 0.0);
  EXPECT_DOUBLE_EQ(c.recall(), 1.0);
  const auto none = score_objects(runs({{20, 10}}), runs({{0, 10}}));
  EXPECT_DOUBLE_EQ(none.precision(), 0.0);
  EXPECT_DOUBLE_EQ(none.recall(), 0.0);
  EXPECT_EQ(score_objects({}, {}).truth, 0U);
}

TEST(SegmentationScore, LabelsTenToNineteenAreNotObjects) {
  // mOSD objects start at k = 2 (label 20): 10-19 name no object and never count.
  EXPECT_EQ(score_objects(runs({{10, 10}, {19, 10}}), runs({{2, 20}})).truth, 0U);
  EXPECT_EQ(truth_object(29), 2U);
  EXPECT_EQ(truth_object(150), 15U);
  EXPECT_TRUE(truth_table(9));
  EXPECT_FALSE(truth_table(0));
  EXPECT_FALSE(truth_table(10));
}

struct Grid {
  std::vector<float> x, y, z;
  Labels truth;
  kernels::PointsView view() const { return {x, y, z}; }
};

/// A 1 m x 1 m table at z = 1 (labels 1) sampled every 1 cm, with one NaN table pixel.
Grid table_grid() {
  Grid g;
  for (int i = 0; i < 100; ++i) {
    for (int j = 0; j < 100; ++j) {
      g.x.push_back(-0.5F + 0.01F * float(i));
      g.y.push_back(-0.5F + 0.01F * float(j));
      g.z.push_back(1.0F);
      g.truth.push_back(1 + std::uint32_t(i % 9));
    }
  }
  g.z[17] = std::nanf("");
  return g;
}

TEST(SegmentationScore, PlaneQualityOfTheTrueAndATiltedPlane) {
  const Grid g = table_grid();
  kernels::Plane truth_plane{{0.0F, 0.0F, -1.0F}, 1.0F};
  const auto right = score_plane(g.view(), g.truth, truth_plane);
  EXPECT_EQ(right.table_points, 9999U);  // the NaN pixel is not a table point
  EXPECT_EQ(right.near, 9999U);
  EXPECT_TRUE(right.correct());
  EXPECT_NEAR(right.angle_deg, 0.0, 1e-3);
  EXPECT_NEAR(right.rms_m, 0.0, 1e-6);
  // Tilted by 2 degrees about y through x = 0: points beyond |x| = 0.01 / tan(2 deg) = 0.286 m
  // are farther than 1 cm, i.e. about 43 % of the table: not correct.
  const double a = 2.0 * 3.14159265358979 / 180.0;
  kernels::Plane tilted{{float(std::sin(a)), 0.0F, -float(std::cos(a))}, float(std::cos(a))};
  const auto wrong = score_plane(g.view(), g.truth, tilted);
  EXPECT_NEAR(wrong.angle_deg, 2.0, 1e-3);
  EXPECT_NEAR(wrong.share(), 0.57, 0.02);
  EXPECT_FALSE(wrong.correct());
  // No table points at all: never correct.
  EXPECT_FALSE(score_plane(g.view(), Labels(g.truth.size(), 0), truth_plane).correct());
}

fs::path frame_dir(const std::string& name) { return testing::unique_dir(name); }

/// A 10 x 10 organized frame: a table row band (labels 1) and one object of 20 pixels (label 20).
kernels::PointCloud small_frame() {
  kernels::PointCloud c;
  c.add_field(kernels::Field::LABEL);
  c.resize(10, 10);
  for (std::size_t i = 0; i < 100; ++i) {
    c.x()[i] = 0.01F * float(i % 10);
    c.y()[i] = 0.01F * float(i / 10);
    c.z()[i] = 1.0F;
    c.label()[i] = i < 20 ? 20U : 1U;
  }
  return c;
}

TEST(SegmentationEval, FramesInNaturalOrderAndBadFramesAreRowsNotScores) {
  const fs::path dir = frame_dir("segeval");
  for (const char* name : {"learn10", "learn2", "learn1"}) {
    ASSERT_TRUE(formats::write_pcd(small_frame(), dir / (std::string(name) + ".pcd")));
  }
  std::ofstream(dir / "broken.pcd") << "VERSION .7\nFIELDS x\n";
  kernels::PointCloud no_labels = small_frame();
  no_labels.remove_field(kernels::Field::LABEL);
  ASSERT_TRUE(formats::write_pcd(no_labels, dir / "learn3.pcd"));
  std::ofstream(dir / "notes.txt") << "not a frame";
  auto frames = labelled_frames(dir);
  ASSERT_TRUE(frames) << frames.error().to_string();
  std::vector<std::string> names;
  for (const auto& f : *frames) names.push_back(f.stem().string());
  EXPECT_EQ(names, (std::vector<std::string>{"broken", "learn1", "learn2", "learn3", "learn10"}));
  // A segmenter that finds the object exactly and takes 1 ms.
  Segmenter exact = [](const kernels::PointCloud& c) {
    SegmenterOutput out;
    out.plane = kernels::Plane{{0.0F, 0.0F, -1.0F}, 1.0F};
    for (std::size_t i = 0; i < c.size(); ++i) out.labels.push_back(i < 20 ? 2U : 1U);
    out.ms = 1.0;
    return out;
  };
  SegEvalOptions options;
  options.names = {{"learn1", "boxes"}, {"learn10", "boxes"}, {"learn2", "other"}};
  options.png_dir = dir / "png";
  auto report = evaluate_segmentation(*frames, "exact", exact, options);
  ASSERT_TRUE(report) << report.error().to_string();
  EXPECT_EQ(report->total.frames, 5U);
  EXPECT_EQ(report->total.failed, 2U);  // broken.pcd, learn3.pcd (no label field)
  EXPECT_NE(report->frames[3].error.find("no label field"), std::string::npos);
  EXPECT_EQ(report->total.objects.truth, 3U);
  EXPECT_EQ(report->total.objects.matched, 3U);
  EXPECT_EQ(report->total.plane_correct, 3U);
  EXPECT_EQ(report->by_category.at("boxes").frames, 2U);
  EXPECT_TRUE(fs::exists(dir / "png" / "learn10.png"));
  EXPECT_FALSE(fs::exists(dir / "png" / "broken.png"));
  const auto json = nlohmann::json::parse(segmentation_json({*report}));
  EXPECT_EQ(json[0]["total"]["failed"], 2);
  EXPECT_EQ(json[0]["frames"][0]["frame"], "broken");
  EXPECT_TRUE(json[0]["frames"][0].contains("error"));
  EXPECT_DOUBLE_EQ(json[0]["total"]["objects"]["recall"].get<double>(), 1.0);
  const std::string md = segmentation_markdown({*report});
  EXPECT_NE(md.find("| exact | 5 | 2 | 3/3 |"), std::string::npos) << md;
  EXPECT_NE(md.find("## Per category"), std::string::npos);
  fs::remove_all(dir);
}

TEST(SegmentationEval, ListingAndNamesErrorsNameTheCulprit) {
  EXPECT_FALSE(labelled_frames("/nonexistent/orthoflow"));
  const fs::path dir = frame_dir("segeval_empty");
  auto none = labelled_frames(dir);
  ASSERT_FALSE(none);
  EXPECT_NE(none.error().message.find("has no .pcd"), std::string::npos);
  std::ofstream(dir / "names.txt") << "# comment\nlearn0 boxes\n\nlearn1 stacked boxes\n";
  auto names = read_frame_names(dir / "names.txt");
  ASSERT_FALSE(names);
  EXPECT_NE(names.error().message.find("names.txt:4"), std::string::npos) << names.error().message;
  std::ofstream(dir / "ok.txt") << "learn0 boxes # the first\nlearn1 stacked\n";
  auto ok = read_frame_names(dir / "ok.txt");
  ASSERT_TRUE(ok);
  EXPECT_EQ(ok->at("learn0"), "boxes");
  EXPECT_EQ(ok->size(), 2U);
  fs::remove_all(dir);
}

TEST(SegmentationEval, ChainSegmenterFindsTheSyntheticObjects) {
  // The product's chain as a segmenter on a synthetic 3-object frame whose labels are written
  // in the mOSD convention: every object found, the plane correct.
  simulation::SceneConfig config;
  config.objects = 3;
  const auto scene = simulation::make_scene(config, 1003U);
  core::Rng rng(1003U);
  kernels::PointCloud cloud;
  simulation::render_scene(scene, {}, rng, cloud);
  Labels truth;
  for (const std::uint32_t l : cloud.label()) {
    const int object = simulation::object_of_label(l);
    truth.push_back(object >= 0                    ? std::uint32_t(object + 2) * 10U
                    : l == simulation::LABEL_TABLE ? 1U
                                                   : 0U);
  }
  kernels::SegmentationParams params;
  params.merge_overlap = 0.3F;  // as the tabletop graph: a bowl's walls are one object
  Segmenter chain = make_chain_segmenter(params, kernels::CandidateParams{});
  const SegmenterOutput out = chain(cloud);
  ASSERT_TRUE(out.error.empty()) << out.error;
  ASSERT_EQ(out.labels.size(), cloud.size());
  const auto c = score_objects(truth, out.labels);
  EXPECT_EQ(c.truth, scene.objects.size());
  EXPECT_EQ(c.matched, c.truth);
  EXPECT_TRUE(score_plane(cloud.points(), truth, out.plane).correct());
  // An unorganized cloud has no per-pixel labels: a failure, not a guess.
  kernels::PointCloud flat;
  flat.resize_unorganized(cloud.size());
  std::copy(cloud.x().begin(), cloud.x().end(), flat.x().begin());
  std::copy(cloud.y().begin(), cloud.y().end(), flat.y().begin());
  std::copy(cloud.z().begin(), cloud.z().end(), flat.z().begin());
  EXPECT_FALSE(chain(flat).error.empty());
}

TEST(FrameLabels, ObjectsTableAndNothing) {
  // Points: in a candidate cluster, in a rejected cluster on the table, on the table, above it,
  // outside the ROI, NaN.
  const std::vector<float> x{0, 0, 0, 0, 5, std::nanf("")}, y{0, 0, 0, 0, 0, 0},
      z{0.9F, 1.0F, 1.01F, 0.8F, 1.0F, 1.0F};
  const std::vector<std::int32_t> cluster_of{1, 0, -1, -1, -1, -1}, slot_of{-1, 0};
  kernels::AxisBox roi{{-1, -1, 0}, {1, 1, 2}};
  Labels out(6, 99);
  kernels::frame_labels({x, y, z}, kernels::Plane{{0, 0, -1}, 1.0F}, 0.02F, roi, cluster_of,
                        slot_of, out);
  EXPECT_EQ(out, (Labels{kernels::FIRST_OBJECT_LABEL, kernels::TABLE_LABEL, 1, 0, 0, 0}));
}

}  // namespace
}  // namespace orthoflow::evaluation
