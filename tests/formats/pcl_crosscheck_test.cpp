// PCL 1.13 as the reference (tests only): every PCD in ../shared read by both readers agrees bit
// for bit, and files written by either reader's writer read back identically in the other.
#include <gtest/gtest.h>

#include <pcl/PCLPointCloud2.h>
#include <pcl/io/pcd_io.h>
#include <pcl/point_types.h>

#include <unistd.h>
#include <filesystem>
#include <string>
#include <vector>

#include "formats/pcd_io.hpp"
#include "formats/point_fields.hpp"
#include "kernels/frame_labels.hpp"
#include "kernels/segmentation_chain.hpp"
#include "test_clouds.hpp"

namespace ofmt = orthoflow::formats;
namespace ok = orthoflow::kernels;
namespace fs = std::filesystem;
using orthoflow::test::bits;

namespace {

std::vector<fs::path> shared_pcds() {
  std::vector<fs::path> out;
  for (const char* sub : {"data", "testdata"}) {
    const fs::path root = fs::path(ORTHOFLOW_SHARED_DIR) / sub;
    if (!fs::exists(root)) { continue; }
    for (const auto& e : fs::recursive_directory_iterator(root)) {
      if (e.is_regular_file() && e.path().extension() == ".pcd") { out.push_back(e.path()); }
    }
  }
  std::sort(out.begin(), out.end());
  return out;
}

std::uint32_t pcl_word(const pcl::PCLPointCloud2& pc, const pcl::PCLPointField& f, std::size_t i) {
  std::uint32_t w = 0;
  std::memcpy(&w, pc.data.data() + i * pc.point_step + f.offset, 4);
  return w;
}

/// Compares every field orthoflow keeps with PCL's generic reading of the same bytes.
void expect_agrees(const pcl::PCLPointCloud2& pc, const ok::PointCloud& ours,
                   const std::string& what) {
  ASSERT_EQ(pc.width, ours.width()) << what;
  ASSERT_EQ(std::max<std::uint32_t>(pc.height, 1), ours.height()) << what;
  for (const pcl::PCLPointField& f : pc.fields) {
    const ofmt::FieldTarget t = ofmt::field_target(f.name);
    if (t == ofmt::FieldTarget::NONE || f.datatype == pcl::PCLPointField::FLOAT64) { continue; }
    std::size_t mismatches = 0;
    for (std::size_t i = 0; i < ours.size(); ++i) {
      std::uint32_t mine = 0;
      if (t == ofmt::FieldTarget::RGB) {
        mine = ours.rgb()[i];
      } else if (t == ofmt::FieldTarget::LABEL) {
        mine = ours.label()[i];
      } else {
        mine = bits(ofmt::float_buffer(ours, t)[i]);
      }
      mismatches += (mine == pcl_word(pc, f, i)) ? 0U : 1U;
    }
    EXPECT_EQ(mismatches, 0U) << what << " field " << f.name;
  }
}

TEST(PclCrossCheck, EverySharedPcdReadsIdentically) {
  const auto files = shared_pcds();
  ASSERT_GE(files.size(), 30U) << "expected the shared data beside the checkout: "
                               << ORTHOFLOW_SHARED_DIR;
  for (const fs::path& p : files) {
    pcl::PCLPointCloud2 pc;
    ASSERT_EQ(pcl::io::loadPCDFile(p.string(), pc), 0) << p;
    auto ours = ofmt::read_pcd(p);
    ASSERT_TRUE(ours) << ours.error().to_string();
    expect_agrees(pc, *ours, p.string());
  }
}

TEST(PclCrossCheck, PclReadsWhatWeWrite) {
  const ok::PointCloud cloud = orthoflow::test::make_cloud(32, 24, true, 11);
  const fs::path dir =
      fs::temp_directory_path() / ("orthoflow_pcl_xcheck_ours_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  for (auto e : {ofmt::PcdEncoding::ASCII, ofmt::PcdEncoding::BINARY,
                 ofmt::PcdEncoding::BINARY_COMPRESSED}) {
    const fs::path p = dir / (std::string(ofmt::to_string(e)) + ".pcd");
    ASSERT_TRUE(ofmt::write_pcd(cloud, p, e));
    pcl::PCLPointCloud2 pc;
    Eigen::Vector4f origin;
    Eigen::Quaternionf orientation;
    ASSERT_EQ(pcl::io::loadPCDFile(p.string(), pc, origin, orientation), 0) << p;
    expect_agrees(pc, cloud, p.string());
    const ok::Viewpoint& vp = cloud.info.viewpoint;
    EXPECT_EQ(origin.head<3>(), Eigen::Vector3f(vp.origin[0], vp.origin[1], vp.origin[2])) << p;
    EXPECT_EQ(orientation.coeffs(),
              Eigen::Vector4f(vp.orientation[1], vp.orientation[2], vp.orientation[3],
                              vp.orientation[0]))
        << p;  // Eigen stores x y z w
    pcl::PointCloud<pcl::PointXYZRGBA> typed;
    ASSERT_EQ(pcl::io::loadPCDFile(p.string(), typed), 0) << p;
    EXPECT_EQ(typed.points[5].rgba, cloud.rgb()[5]) << p;
    pcl::PointCloud<pcl::PointXYZRGB>
        rgb_typed;  // PCL maps our `rgba U 4` onto PointXYZRGB's rgb too
    ASSERT_EQ(pcl::io::loadPCDFile(p.string(), rgb_typed), 0) << p;
    EXPECT_EQ(rgb_typed.points[7].rgba, cloud.rgb()[7]) << p;
  }
  fs::remove_all(dir);
}

TEST(PclCrossCheck, WeReadWhatPclWrites) {
  pcl::PointCloud<pcl::PointXYZRGBA> typed(16, 8);
  const ok::PointCloud ref = orthoflow::test::make_cloud(16, 8, true, 21);
  ofmt::to_aos<pcl::PointXYZRGBA>(
      ref, std::span<pcl::PointXYZRGBA>(typed.points.data(), typed.points.size()));
  typed.sensor_origin_ = Eigen::Vector4f(0.25F, -2.0F, 1.5F, 0.0F);
  typed.sensor_orientation_ = Eigen::Quaternionf(0.5F, -0.5F, 0.5F, -0.5F);  // w x y z
  const fs::path dir =
      fs::temp_directory_path() / ("orthoflow_pcl_xcheck_pcl_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  pcl::PCDWriter writer;
  const fs::path a = dir / "a.pcd", b = dir / "b.pcd", c = dir / "c.pcd";
  ASSERT_EQ(writer.writeASCII(a.string(), typed, 9), 0);
  ASSERT_EQ(writer.writeBinary(b.string(), typed), 0);
  ASSERT_EQ(writer.writeBinaryCompressed(c.string(), typed), 0);
  for (const fs::path& p : {b, c}) {  // binary encodings carry the exact bits
    auto ours = ofmt::read_pcd(p);
    ASSERT_TRUE(ours) << ours.error().to_string();
    ASSERT_EQ(ours->size(), ref.size());
    for (std::size_t i = 0; i < ref.size(); ++i) {
      ASSERT_EQ(bits(ours->x()[i]), bits(ref.x()[i])) << p << " point " << i;
      ASSERT_EQ(ours->rgb()[i], ref.rgb()[i]) << p << " point " << i;
    }
    ok::PointCloud adapted;  // the AoS adapter over PCL's own point struct gives the same cloud
    ofmt::from_aos<pcl::PointXYZRGBA>(
        std::span<const pcl::PointXYZRGBA>(typed.points.data(), typed.points.size()), adapted);
    for (std::size_t i = 0; i < ref.size(); ++i) {
      ASSERT_EQ(bits(adapted.z()[i]), bits(ours->z()[i])) << "point " << i;
      ASSERT_EQ(adapted.rgb()[i], ours->rgb()[i]) << "point " << i;
    }
    const ok::Viewpoint expected{{0.25F, -2.0F, 1.5F}, {0.5F, -0.5F, 0.5F, -0.5F}};
    EXPECT_EQ(ours->info.viewpoint, expected) << p;
  }
  auto ascii = ofmt::read_pcd(a);
  ASSERT_TRUE(ascii) << ascii.error().to_string();
  pcl::PCLPointCloud2 pc;
  ASSERT_EQ(pcl::io::loadPCDFile(a.string(), pc), 0);
  expect_agrees(pc, *ascii, a.string());  // the same text parsed by both gives the same bits
  fs::remove_all(dir);
}

TEST(PclCrosscheck, LabelsOutFileReadsIntoPclsLabelledPoints) {
  // What `orthoflow segment --labels-out` writes: the frame with our per-point labels in place of
  // its own (0 none, 1 table, k >= 2 object). PCL reads it into PointXYZRGBL organized, label for
  // label and bit for bit.
  auto frame = ofmt::read_pcd(fs::path(ORTHOFLOW_SHARED_DIR) / "data/mosd_learn/learn13.pcd");
  ASSERT_TRUE(frame) << frame.error().to_string();
  ok::SegmentationChain chain(frame->size(), ok::SegmentationParams{});
  auto seg = chain.run(frame->view());
  ASSERT_TRUE(seg) << seg.error().to_string();
  ok::frame_labels(frame->points(), seg->plane.plane, 0.02F, ok::SegmentationParams{}.roi,
                   seg->labels, seg->candidate_of, frame->label());
  const fs::path dir =
      fs::temp_directory_path() / ("orthoflow_labels_out_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  const fs::path file = dir / "labels.pcd";
  ASSERT_TRUE(ofmt::write_pcd(*frame, file));
  pcl::PointCloud<pcl::PointXYZRGBL> pcl_cloud;
  ASSERT_EQ(pcl::io::loadPCDFile(file.string(), pcl_cloud), 0);
  ASSERT_EQ(pcl_cloud.width, frame->width());
  ASSERT_EQ(pcl_cloud.height, frame->height());
  std::size_t objects = 0, table = 0;
  for (std::size_t i = 0; i < frame->size(); ++i) {
    ASSERT_EQ(pcl_cloud[i].label, frame->label()[i]) << "point " << i;
    ASSERT_EQ(bits(pcl_cloud[i].z), bits(frame->z()[i])) << "point " << i;
    objects += pcl_cloud[i].label >= ok::FIRST_OBJECT_LABEL ? 1U : 0U;
    table += pcl_cloud[i].label == ok::TABLE_LABEL ? 1U : 0U;
  }
  EXPECT_GT(table, 100000U);  // learn13: a table and three boxes
  EXPECT_GT(objects, 3000U);
  fs::remove_all(dir);
}

}  // namespace
