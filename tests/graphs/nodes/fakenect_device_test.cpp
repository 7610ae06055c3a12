// fakenect's device.json from and to the Kinect driver's calibration: the round trip keeps every
// value fakenect stores, the layout is fakenect's, and a missing or out-of-range key is refused by
// name.
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include "graphs/nodes/fakenect_calibration.hpp"

namespace orthoflow::graphs {
namespace {

drivers::kinect::Calibration sample() {
  drivers::kinect::Calibration c;
  for (std::size_t i = 0; i < c.reg.words.size(); ++i)
    c.reg.words[i] = static_cast<std::int32_t>(i * 1000) - 7000;
  c.pad = {0, 8, 1};
  c.zero_plane.reference_pixel_size_mm = 0.1052F;
  c.zero_plane.reference_distance_mm = 118.5F;
  c.const_shift = 199;
  return c;
}

TEST(FakenectDevice, RoundTripKeepsWhatFakenectStores) {
  const auto c = sample();
  const std::string text = fakenect_device_json(c);
  auto back = parse_fakenect_device(text, "device.json");
  ASSERT_TRUE(back.has_value()) << back.error().to_string();
  for (std::size_t i = 0; i < 29; ++i) {
    const std::string_view name = drivers::kinect::reg_info_name(i);
    const bool dropped = name == "dx_center" || name == "rollout_blank" || name == "rollout_size" ||
                         name == "back_comp1" || name == "back_comp2";
    EXPECT_EQ(back->reg.words[i], dropped ? 0 : c.reg.words[i]) << name;
  }
  EXPECT_EQ(back->pad.end_lines, 8);
  EXPECT_EQ(back->pad.cropping_lines, 1);
  EXPECT_EQ(back->zero_plane.reference_pixel_size_mm, 0.1052F);
  EXPECT_EQ(back->zero_plane.reference_distance_mm, 118.5F);
  EXPECT_EQ(back->zero_plane.dcmos_rcmos_dist_cm, c.zero_plane.dcmos_rcmos_dist_cm);
  EXPECT_EQ(back->const_shift, 199);
}

TEST(FakenectDevice, LayoutIsFakenects) {
  const auto j = nlohmann::json::parse(fakenect_device_json(sample()));
  ASSERT_TRUE(j.contains("reg_info") && j.contains("const_shift"));
  EXPECT_EQ(j["reg_info"].size(), 26U);  // 24 words + pad_info + zero_plane_info
  EXPECT_TRUE(j["reg_info"]["pad_info"].contains("cropping_lines"));
  EXPECT_TRUE(j["reg_info"]["zero_plane_info"].contains("reference_pixel_size"));
  EXPECT_EQ(j["reg_info"]["dydydy_start"], sample().reg.words[28]);
  EXPECT_FALSE(j["reg_info"].contains("dx_center"));
}

TEST(FakenectDevice, RefusesMissingAndOutOfRangeKeysByName) {
  std::string text = fakenect_device_json(sample());
  auto missing = text;
  missing.replace(missing.find("\"dydydy_start\""), 14, "\"nothing\"");
  const auto m = parse_fakenect_device(missing, "device.json");
  ASSERT_FALSE(m.has_value());
  EXPECT_NE(m.error().message.find("dydydy_start"), std::string::npos);
  auto zero = nlohmann::json::parse(text);
  zero["reg_info"]["zero_plane_info"]["reference_pixel_size"] = 0.0;
  EXPECT_EQ(parse_fakenect_device(zero.dump(), "d").error().code,
            formats::IoError::Code::BAD_NUMBER);
  zero["reg_info"]["zero_plane_info"]["reference_pixel_size"] = "0.1";
  EXPECT_EQ(parse_fakenect_device(zero.dump(), "d").error().code,
            formats::IoError::Code::BAD_HEADER);
  EXPECT_FALSE(parse_fakenect_device("[1, 2]", "d").has_value());
  EXPECT_FALSE(parse_fakenect_device("{\"reg_info\": ", "d").has_value());
  EXPECT_FALSE(parse_fakenect_device("", "d").has_value());
  auto shift = nlohmann::json::parse(text);
  shift["const_shift"] = 1e300;
  EXPECT_FALSE(parse_fakenect_device(shift.dump(), "d").has_value());
}

}  // namespace
}  // namespace orthoflow::graphs
