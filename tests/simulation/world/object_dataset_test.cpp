// The object-view dataset generator: tree layout, content, determinism and errors.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>

#include "formats/pcd_io.hpp"
#include "simulation/world/object_dataset.hpp"

namespace orthoflow::simulation {
namespace {

namespace fs = std::filesystem;

fs::path fresh_dir(const char* name) {
  const fs::path dir = fs::path(ORTHOFLOW_BINARY_DIR) / "test_output" / name;
  fs::remove_all(dir);
  return dir;
}

DatasetConfig small_config() {
  DatasetConfig c;
  c.categories = {Category::MUG, Category::PLATE, Category::KNIFE};
  c.instances = 2;
  c.views = 2;
  c.seed = 3;
  // The same field of view at half resolution (320x240): a quarter of the rays, for quicker tests.
  c.render.intrinsics = DepthIntrinsics{287.9, 287.9, 159.5, 119.5, 320, 240};
  return c;
}

TEST(ObjectDataset, WritesTheExpectedTreeAndEveryViewHasObjectPoints) {
  const fs::path dir = fresh_dir("object_dataset_tree");
  const auto summary_result = write_object_dataset(small_config(), dir);
  ASSERT_TRUE(summary_result) << summary_result.error().to_string();
  EXPECT_EQ(summary_result.value().files, 12U);
  EXPECT_EQ(summary_result.value().categories, 3U);
  EXPECT_GE(summary_result.value().min_points, 20U);
  std::size_t files = 0;
  for (const auto& entry : fs::recursive_directory_iterator(dir)) {
    files += entry.is_regular_file();
  }
  EXPECT_EQ(files, 12U);
  EXPECT_TRUE(fs::exists(dir / "mug" / "mug_00" / "view_000.pcd"));
  EXPECT_TRUE(fs::exists(dir / "knife" / "knife_01" / "view_001.pcd"));
  for (const char* rel :
       {"mug/mug_01/view_001.pcd", "plate/plate_00/view_000.pcd", "knife/knife_00/view_001.pcd"}) {
    const auto cloud_result = formats::read_pcd(dir / rel);
    ASSERT_TRUE(cloud_result) << cloud_result.error().to_string();
    const kernels::PointCloud& c = cloud_result.value();
    EXPECT_GE(c.size(), 20U) << rel;
    EXPECT_FALSE(c.organized());
    EXPECT_TRUE(c.has(kernels::Field::RGB));
    for (std::size_t i = 0; i < c.size(); ++i) {
      ASSERT_TRUE(std::isfinite(c.x()[i]) && std::isfinite(c.y()[i]) && std::isfinite(c.z()[i]));
      // Sensor frame: in front of the camera, within the configured distances (plus object size).
      ASSERT_GT(c.z()[i], 0.45F);
      ASSERT_LT(c.z()[i], 1.7F);
    }
  }
}

TEST(ObjectDataset, ViewsAreSeededAndSpanTheConfiguredRanges) {
  const DatasetConfig c = small_config();
  double min_el = 1e9, max_el = -1e9, min_az = 1e9, max_az = -1e9;
  for (std::uint32_t v = 0; v < 50; ++v) {
    const ViewSpec s = dataset_view(c, Category::MUG, 0, v);
    const ViewSpec again = dataset_view(c, Category::MUG, 0, v);
    EXPECT_EQ(s.elevation_rad, again.elevation_rad);
    EXPECT_GE(s.distance_m, 0.6);
    EXPECT_LE(s.distance_m, 1.5);
    min_el = std::min(min_el, s.elevation_rad * 180 / M_PI);
    max_el = std::max(max_el, s.elevation_rad * 180 / M_PI);
    min_az = std::min(min_az, s.azimuth_rad);
    max_az = std::max(max_az, s.azimuth_rad);
  }
  EXPECT_GE(min_el, 20.0);
  EXPECT_LE(max_el, 70.0);
  EXPECT_GT(max_el - min_el, 35.0);
  EXPECT_GT(max_az - min_az, 5.0);
  DatasetConfig other = c;
  other.seed = 4;
  EXPECT_NE(dataset_view(c, Category::MUG, 0, 0).azimuth_rad,
            dataset_view(other, Category::MUG, 0, 0).azimuth_rad);
}

TEST(ObjectDataset, SameSeedSameBytes) {
  const ObjectModel mug = make_object_model(Category::MUG, 1, 9);
  const ViewSpec view{0.7, 1.0, 0.9};
  kernels::PointCloud frame, a, b;
  core::Rng ra(5), rb(5), rc(6);
  ASSERT_GT(render_object_view(mug, view, small_config().render, ra, frame, a), 150U);
  render_object_view(mug, view, small_config().render, rb, frame, b);
  EXPECT_EQ(formats::encode_pcd(a, formats::PcdEncoding::BINARY),
            formats::encode_pcd(b, formats::PcdEncoding::BINARY));
  render_object_view(mug, view, small_config().render, rc, frame, b);
  EXPECT_NE(formats::encode_pcd(a, formats::PcdEncoding::BINARY),
            formats::encode_pcd(b, formats::PcdEncoding::BINARY));
}

TEST(ObjectDataset, WindowedViewHasExactlyTheObjectPointsOfTheFullFrame) {
  RenderOptions exact;  // no noise: the full frame and the window must agree bit for bit
  exact.depth.sigma_raw = 0.0;
  for (Category cat : {Category::TEAPOT, Category::FORK, Category::VASE}) {
    const ObjectModel model = make_object_model(cat, 2, 4);
    for (const ViewSpec& view : {ViewSpec{0.4, 0.3, 0.6}, ViewSpec{1.2, 4.0, 1.4}}) {
      kernels::PointCloud frame, windowed, full;
      core::Rng r1(1), r2(1);
      const std::size_t n = render_object_view(model, view, exact, r1, frame, windowed);
      Scene scene;
      scene.table = TableSpec{view.distance_m, view.elevation_rad, 3.0, 3.0, 0.0};
      scene.objects.push_back(PlacedObject{model, 0.0, 0.0, view.azimuth_rad});
      render_scene(scene, exact, r2, full);
      std::size_t k = 0;
      for (std::size_t i = 0; i < full.size(); ++i) {
        if (full.label()[i] != OBJECT_LABEL_BASE) { continue; }
        ASSERT_LT(k, n);
        ASSERT_EQ(full.x()[i], windowed.x()[k]);
        ASSERT_EQ(full.z()[i], windowed.z()[k]);
        ++k;
      }
      EXPECT_EQ(k, n) << category_name(cat);
      EXPECT_GT(n, 50U);
      EXPECT_LT(frame.size(),
                view.distance_m > 1.0 ? full.size() / 4 : full.size());  // a part of the image
    }
  }
}

TEST(ObjectDataset, InstancesVaryWithinACategory) {
  const ObjectModel a = make_object_model(Category::BOTTLE, 0, 1);
  const ObjectModel b = make_object_model(Category::BOTTLE, 1, 1);
  const ObjectModel c = make_object_model(Category::BOTTLE, 0, 2);
  EXPECT_NE(a.height, b.height);
  EXPECT_NE(a.height, c.height);
  EXPECT_EQ(a.height, make_object_model(Category::BOTTLE, 0, 1).height);
  // Categories keep their character: a plate is flat and wide, a bottle tall and narrow.
  for (std::uint32_t i = 0; i < 10; ++i) {
    const ObjectModel plate = make_object_model(Category::PLATE, i, 7);
    const ObjectModel bottle = make_object_model(Category::BOTTLE, i, 7);
    EXPECT_LT(plate.height, 0.3 * plate.footprint_radius);
    EXPECT_GT(bottle.height, 3.0 * bottle.footprint_radius);
  }
}

TEST(ObjectDataset, ErrorsSayWhat) {
  DatasetConfig bad = small_config();
  bad.views = 0;
  auto bad_result = write_object_dataset(bad, fresh_dir("object_dataset_bad"));
  ASSERT_FALSE(bad_result);
  EXPECT_EQ(bad_result.error().code, DatasetError::Code::BAD_CONFIG);
  EXPECT_NE(bad_result.error().to_string().find("views"), std::string::npos);

  // Issue 16: an empty path (the working directory) and a category listed twice are refused, and
  // nothing is written.
  DatasetConfig one_view = small_config();
  one_view.instances = one_view.views = 1;
  auto empty_result = write_object_dataset(one_view, "");
  ASSERT_FALSE(empty_result);
  EXPECT_EQ(empty_result.error().code, DatasetError::Code::BAD_CONFIG);
  EXPECT_NE(empty_result.error().message.find("empty path"), std::string::npos);
  DatasetConfig twice = one_view;
  twice.categories = {Category::MUG, Category::BOWL, Category::MUG};
  const fs::path twice_dir = fresh_dir("object_dataset_twice");
  auto twice_result = write_object_dataset(twice, twice_dir);
  ASSERT_FALSE(twice_result);
  EXPECT_EQ(twice_result.error().code, DatasetError::Code::BAD_CONFIG);
  EXPECT_NE(twice_result.error().message.find("category 'mug' is listed twice"), std::string::npos)
      << twice_result.error().message;
  EXPECT_FALSE(fs::exists(twice_dir));

  // A knife lying flat seen from straight above at 0.5 m is nearer than the sensor's minimum range.
  DatasetConfig blind = small_config();
  blind.categories = {Category::KNIFE};
  blind.instances = blind.views = 1;
  blind.min_elevation_deg = blind.max_elevation_deg = 90.0;
  blind.min_distance_m = blind.max_distance_m = 0.5;
  auto blind_result = write_object_dataset(blind, fresh_dir("object_dataset_blind"));
  ASSERT_FALSE(blind_result);
  EXPECT_EQ(blind_result.error().code, DatasetError::Code::EMPTY_VIEW);

  const fs::path file = fresh_dir("object_dataset_file");
  fs::create_directories(file.parent_path());
  std::ofstream(file) << "not a directory";
  DatasetConfig one = small_config();
  one.instances = one.views = 1;
  auto write_result = write_object_dataset(one, file);
  ASSERT_FALSE(write_result);
  EXPECT_EQ(write_result.error().code, DatasetError::Code::WRITE_FAILED);
  EXPECT_NE(write_result.error().message.find("object_dataset_file"), std::string::npos);
}

}  // namespace
}  // namespace orthoflow::simulation
