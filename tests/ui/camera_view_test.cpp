// The camera image (ui/camera_view.hpp): the pinhole fit recovers a camera from its own points and
// refuses points that are not a pinhole grid; objects' 3D boxes land where the camera sees them;
// the PNG is a real PNG of the image's size, for colour, depth, holes and an empty image.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include "engine/object_list_payload.hpp"
#include "tests/support/pinhole_image.hpp"
#include "ui/camera_view.hpp"

namespace orthoflow::ui {
namespace {

constexpr double FX = 262.5, FY = 262.5, CX = 159.75, CY = 119.75;  // a Kinect at 320 x 240

// A camera looking at a wall 1.5 m away with a box-shaped object in front, at 320 x 240.
graphs::CameraImage wall(bool colour) {
  graphs::CameraImage image =
      test::pinhole_image(320, 240, FX, CX, CY, [](std::uint32_t i, std::uint32_t j) {
        return (i > 100 && i < 140 && j > 80 && j < 160) ? 1.0F : 1.5F;
      });
  image.frame_id = 9;
  image.step = 2;
  if (colour) image.rgb.assign(image.z.size(), 0xFF336699U);
  image.z[5] = std::numeric_limits<float>::quiet_NaN();  // a hole
  return image;
}

ObjectView object(std::uint64_t track, float x0, float y0, float z0, float x1, float y1, float z1) {
  ObjectView o;
  o.track_id = track;
  o.bbox_min[0] = x0, o.bbox_min[1] = y0, o.bbox_min[2] = z0;
  o.bbox_max[0] = x1, o.bbox_max[1] = y1, o.bbox_max[2] = z1;
  return o;
}

// Width and height from a PNG's IHDR chunk.
std::pair<int, int> png_size(const std::string& png) {
  if (png.size() < 24 || png.compare(0, 8, "\x89PNG\r\n\x1a\n") != 0) return {-1, -1};
  auto be32 = [&](std::size_t at) {
    return (static_cast<unsigned char>(png[at]) << 24) |
           (static_cast<unsigned char>(png[at + 1]) << 16) |
           (static_cast<unsigned char>(png[at + 2]) << 8) | static_cast<unsigned char>(png[at + 3]);
  };
  return {static_cast<int>(be32(16)), static_cast<int>(be32(20))};
}

TEST(CameraView, ThePinholeFitRecoversTheCamera) {
  const PinholeFit fit = fit_pinhole(wall(false));
  ASSERT_TRUE(fit.ok);
  EXPECT_NEAR(fit.fx, FX, 1e-2);
  EXPECT_NEAR(fit.fy, FY, 1e-2);
  EXPECT_NEAR(fit.cx, CX, 1e-2);
  EXPECT_NEAR(fit.cy, CY, 1e-2);
  EXPECT_LT(fit.rms_px, 0.01);
}

TEST(CameraView, PointsThatAreNotAPinholeGridGetNoFit) {
  graphs::CameraImage image = wall(false);
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> any(-1.0F, 1.0F);
  for (std::size_t k = 0; k < image.x.size(); ++k) image.x[k] = any(rng);  // scrambled columns
  EXPECT_FALSE(fit_pinhole(image).ok);
  graphs::CameraImage few = wall(false);
  for (float& z : few.z) z = std::numeric_limits<float>::quiet_NaN();
  few.z[0] = 1.0F;
  EXPECT_FALSE(fit_pinhole(few).ok);  // too few measured pixels
  EXPECT_FALSE(fit_pinhole(graphs::CameraImage{}).ok);
  EXPECT_TRUE(
      project_boxes(fit_pinhole(few), 320, 240, {object(1, 0, 0, 1, 0.1F, 0.1F, 1.1F)}).empty());
}

TEST(CameraView, BoxesLandWhereTheCameraSeesThem) {
  const PinholeFit fit = fit_pinhole(wall(false));
  ObjectView fragment = object(4, 0, 0, 1, 0.1F, 0.1F, 1.1F);
  fragment.flags = engine::OBJECT_FRAGMENT;
  const std::vector<ObjectView> objects = {
      object(2, -0.1F, -0.05F, 1.0F, 0.1F, 0.05F, 1.2F),  // centred
      object(0, -0.1F, -0.05F, 1.0F, 0.1F, 0.05F, 1.2F),  // untracked: not drawn
      fragment,                                           // a piece of another: not drawn
      object(3, 5.0F, 0, 1.0F, 5.2F, 0.1F, 1.1F),         // beside the image
      object(5, 0, 0, -1.0F, 0.1F, 0.1F, 0.5F),           // behind the camera
      object(6, 0.4F, 0.2F, 1.0F, 0.9F, 0.3F, 1.2F),      // cut by the image's right edge
  };
  const std::vector<ImageBox> boxes = project_boxes(fit, 320, 240, objects);
  ASSERT_EQ(boxes.size(), 2U);
  EXPECT_EQ(boxes[0].track, 2U);
  EXPECT_NEAR(boxes[0].u0, CX - FX * 0.1, 0.05);  // the nearer face spans the widest
  EXPECT_NEAR(boxes[0].u1, CX + FX * 0.1, 0.05);
  EXPECT_NEAR(boxes[0].v0, CY - FY * 0.05, 0.05);
  EXPECT_NEAR(boxes[0].v1, CY + FY * 0.05, 0.05);
  EXPECT_EQ(boxes[1].track, 6U);
  EXPECT_EQ(boxes[1].u1, 320.0F);
  EXPECT_LT(boxes[1].u0, 320.0F);
}

TEST(CameraView, DrawsAPngOfTheImagesSize) {
  std::vector<ObjectView> objects = {object(2, -0.1F, -0.05F, 1.0F, 0.1F, 0.05F, 1.2F)};
  objects[0].label = "mug";
  objects[0].unknown = false;
  for (const bool colour : {true, false}) {
    const std::string png = render_camera_png(wall(colour), objects);
    EXPECT_EQ(png_size(png), std::make_pair(320, 240)) << colour;
  }
  // Only holes: drawn all dark, no boxes (no fit), still a PNG.
  graphs::CameraImage holes = wall(false);
  for (float& z : holes.z) z = std::numeric_limits<float>::quiet_NaN();
  EXPECT_EQ(png_size(render_camera_png(holes, objects)), std::make_pair(320, 240));
  EXPECT_EQ(render_camera_png(graphs::CameraImage{}, objects), "");
  graphs::CameraImage short_arrays = wall(false);
  short_arrays.z.resize(10);
  EXPECT_EQ(render_camera_png(short_arrays, objects), "");
}

}  // namespace
}  // namespace orthoflow::ui
