#include "drivers/kinect/kinect_protocol.hpp"

#include <bit>
#include <cmath>
#include <cstring>

namespace orthoflow::drivers::kinect {

const char* to_string(Model model) noexcept {
  switch (model) {
    case Model::K1414:
      return "1414";
    case Model::K1473:
      return "1473";
    case Model::K4W:
      return "k4w";
  }
  return "unknown";
}

std::optional<Model> detect_model(const UsbDeviceInfo& camera) noexcept {
  if (camera.vendor != VENDOR_MICROSOFT) return std::nullopt;
  if (camera.product == PID_CAMERA_K4W) return Model::K4W;
  if (camera.product != PID_CAMERA) return std::nullopt;
  return camera.bcd_device == BCD_MODEL_1414 ? Model::K1414 : Model::K1473;
}

std::optional<CommandFrame> encode_command(std::uint16_t opcode, std::uint16_t tag,
                                           std::span<const std::byte> payload) noexcept {
  if (payload.size() % 2 != 0 || payload.size() > MAX_COMMAND_PAYLOAD) return std::nullopt;
  CommandFrame frame;
  const std::span<std::byte> out(frame.bytes);
  out[0] = std::byte{0x47};  // 'G'
  out[1] = std::byte{0x4D};  // 'M'
  store_le16(out, 2, static_cast<std::uint16_t>(payload.size() / 2));
  store_le16(out, 4, opcode);
  store_le16(out, 6, tag);
  if (!payload.empty()) std::memcpy(out.data() + HEADER_BYTES, payload.data(), payload.size());
  frame.size = HEADER_BYTES + payload.size();
  return frame;
}

const char* to_string(ReplyCheck check) noexcept {
  switch (check) {
    case ReplyCheck::OK:
      return "ok";
    case ReplyCheck::NOT_READY:
      return "not_ready";
    case ReplyCheck::TOO_SHORT:
      return "too_short";
    case ReplyCheck::BAD_MAGIC:
      return "bad_magic";
    case ReplyCheck::WRONG_OPCODE:
      return "wrong_opcode";
    case ReplyCheck::WRONG_TAG:
      return "wrong_tag";
    case ReplyCheck::BAD_LENGTH:
      return "bad_length";
  }
  return "unknown";
}

Reply check_reply(std::span<const std::byte> received, std::uint16_t opcode,
                  std::uint16_t tag) noexcept {
  if (received.empty() || received.size() == REPLY_BUFFER_BYTES) return {ReplyCheck::NOT_READY, {}};
  if (received.size() < HEADER_BYTES) return {ReplyCheck::TOO_SHORT, {}};
  if (received[0] != std::byte{0x52} || received[1] != std::byte{0x42}) {
    return {ReplyCheck::BAD_MAGIC, {}};
  }
  if (load_le16(received, 4) != opcode) return {ReplyCheck::WRONG_OPCODE, {}};
  if (load_le16(received, 6) != tag) return {ReplyCheck::WRONG_TAG, {}};
  if (std::size_t{load_le16(received, 2)} * 2 != received.size() - HEADER_BYTES) {
    return {ReplyCheck::BAD_LENGTH, {}};
  }
  return {ReplyCheck::OK, received.subspan(HEADER_BYTES)};
}

namespace {

constexpr RegisterWrite DEPTH_11[] = {{0x0105, 0x00, 0}, {0x0006, 0x00, 0}, {0x0012, 0x03, 0},
                                      {0x0013, 0x01, 0}, {0x0014, 0x1E, 0}, {0x0006, 0x02, 0},
                                      {0x0017, 0x00, 0}};
constexpr RegisterWrite DEPTH_10[] = {{0x0105, 0x00, 0}, {0x0006, 0x00, 0}, {0x0012, 0x02, 0},
                                      {0x0013, 0x01, 0}, {0x0014, 0x1E, 0}, {0x0006, 0x02, 0},
                                      {0x0017, 0x00, 0}};
constexpr RegisterWrite DEPTH_STOP[] = {{0x0006, 0x00, 0}};
constexpr RegisterWrite BAYER[] = {
    {0x000C, 0x00, 0}, {0x000D, 0x01, 0}, {0x000E, 0x1E, 0}, {0x0005, 0x01, 0}, {0x0047, 0x00, 0}};
constexpr RegisterWrite UYVY[] = {
    {0x000C, 0x05, 0}, {0x000D, 0x01, 0}, {0x000E, 0x0F, 0}, {0x0005, 0x01, 0}, {0x0047, 0x00, 0}};
constexpr RegisterWrite BAYER_HIGH[] = {
    {0x000C, 0x00, 0}, {0x000D, 0x02, 0}, {0x000E, 0x0F, 0}, {0x0005, 0x01, 0}, {0x0047, 0x00, 0}};
constexpr RegisterWrite IR[] = {{0x0019, 0x00, 0}, {0x001A, 0x01, 0}, {0x001B, 0x1E, 0},
                                {0x0105, 0x00, 0}, {0x0005, 0x03, 0}, {0x0048, 0x00, 0}};
// 1280x1024 IR only starts after a dummy depth start/stop (a firmware quirk, KINECT_V1.md 5.2).
constexpr RegisterWrite IR_HIGH[] = {
    {0x0013, 0x01, 0}, {0x0014, 0x1E, 0}, {0x0006, 0x02, 0}, {0x0006, 0x00, 0}, {0x0019, 0x00, 0},
    {0x001A, 0x02, 0}, {0x001B, 0x0F, 0}, {0x0105, 0x00, 0}, {0x0005, 0x03, 0}, {0x0048, 0x00, 0}};
constexpr RegisterWrite VIDEO_STOP[] = {{0x0005, 0x00, 0}};
constexpr RegisterWrite NEAR_ON[] = {{0x0015, 0x07, 0}, {0x02EF, 0x00, 100}};
constexpr RegisterWrite NEAR_OFF[] = {{0x0015, 0x1E, 0}, {0x02EF, 0x190, 100}};

constexpr const char* REG_INFO_NAMES[29] = {"dx_center",
                                            "ax",
                                            "bx",
                                            "cx",
                                            "dx",
                                            "dx_start",
                                            "ay",
                                            "by",
                                            "cy",
                                            "dy",
                                            "dy_start",
                                            "dx_beta_start",
                                            "dy_beta_start",
                                            "rollout_blank",
                                            "rollout_size",
                                            "dx_beta_inc",
                                            "dy_beta_inc",
                                            "dxdx_start",
                                            "dxdy_start",
                                            "dydx_start",
                                            "dydy_start",
                                            "dxdxdx_start",
                                            "dydxdx_start",
                                            "dxdxdy_start",
                                            "dydxdy_start",
                                            "back_comp1",
                                            "dydydx_start",
                                            "back_comp2",
                                            "dydydy_start"};

float load_le_float(std::span<const std::byte> bytes, std::size_t offset) noexcept {
  std::uint32_t bits = 0;
  for (std::size_t i = 0; i < 4; ++i) {
    bits |= std::to_integer<std::uint32_t>(bytes[offset + i]) << (8U * i);
  }
  return std::bit_cast<float>(bits);
}

bool within(float value, float lo, float hi) noexcept { return value >= lo && value <= hi; }

}  // namespace

RegisterScript depth_start_script(DepthFormat format) noexcept {
  return format == DepthFormat::BITS_11 ? RegisterScript(DEPTH_11) : RegisterScript(DEPTH_10);
}
RegisterScript depth_stop_script() noexcept { return DEPTH_STOP; }
RegisterScript video_start_script(VideoFormat format) noexcept {
  switch (format) {
    case VideoFormat::BAYER:
      return BAYER;
    case VideoFormat::UYVY:
      return UYVY;
    case VideoFormat::IR_10BIT:
      return IR;
    case VideoFormat::BAYER_HIGH:
      return BAYER_HIGH;
    case VideoFormat::IR_HIGH:
      return IR_HIGH;
  }
  return BAYER;
}
RegisterScript video_stop_script() noexcept { return VIDEO_STOP; }
RegisterScript near_mode_script(bool on) noexcept { return on ? NEAR_ON : NEAR_OFF; }

const char* reg_info_name(std::size_t index) noexcept {
  return index < 29 ? REG_INFO_NAMES[index] : "unknown";
}

const char* to_string(ParseCheck check) noexcept {
  switch (check) {
    case ParseCheck::OK:
      return "ok";
    case ParseCheck::WRONG_SIZE:
      return "wrong_size";
    case ParseCheck::DEVICE_STATUS:
      return "device_status";
    case ParseCheck::NOT_FINITE:
      return "not_finite";
    case ParseCheck::OUT_OF_RANGE:
      return "out_of_range";
  }
  return "unknown";
}

ParseCheck parse_fixed_params(std::span<const std::byte> payload, Model model, ZeroPlane& out,
                              float& reported_rcmos) noexcept {
  const std::size_t expected = model == Model::K1414 ? 322 : 334;
  if (payload.size() != expected) return ParseCheck::WRONG_SIZE;
  if (load_le16(payload, 0) != 0) return ParseCheck::DEVICE_STATUS;
  const float emitter = load_le_float(payload, 94);
  const float rcmos = load_le_float(payload, 98);
  const float ref_dist = load_le_float(payload, 102);
  const float ref_pix = load_le_float(payload, 106);
  if (!std::isfinite(emitter) || !std::isfinite(rcmos) || !std::isfinite(ref_dist) ||
      !std::isfinite(ref_pix)) {
    return ParseCheck::NOT_FINITE;
  }
  if (!within(emitter, 1.0F, 20.0F) || !within(ref_dist, 50.0F, 500.0F) ||
      !within(ref_pix, 0.05F, 0.2F)) {
    return ParseCheck::OUT_OF_RANGE;
  }
  out.dcmos_emitter_dist_cm = emitter;
  out.dcmos_rcmos_dist_cm = 2.4F;  // libfreenect overrides the device's ~2.3 cm to match OpenNI
  out.reference_distance_mm = ref_dist;
  out.reference_pixel_size_mm = ref_pix;
  reported_rcmos = rcmos;
  return ParseCheck::OK;
}

ParseCheck parse_pad_info(std::span<const std::byte> payload, PadInfo& out) noexcept {
  if (payload.size() != 8) return ParseCheck::WRONG_SIZE;
  if (load_le16(payload, 0) != 0) return ParseCheck::DEVICE_STATUS;
  out.start_lines = load_le16(payload, 2);
  out.end_lines = load_le16(payload, 4);
  out.cropping_lines = load_le16(payload, 6);
  if (out.start_lines > 1024 || out.end_lines > 1024 || out.cropping_lines > 1024) {
    return ParseCheck::OUT_OF_RANGE;
  }
  return ParseCheck::OK;
}

ParseCheck parse_reg_info(std::span<const std::byte> payload, RegInfo& out) noexcept {
  if (payload.size() != 2 + 29 * 4) return ParseCheck::WRONG_SIZE;
  if (load_le16(payload, 0) != 0) return ParseCheck::DEVICE_STATUS;
  for (std::size_t i = 0; i < 29; ++i) {
    std::uint32_t bits = 0;
    for (std::size_t b = 0; b < 4; ++b) {
      bits |= std::to_integer<std::uint32_t>(payload[2 + 4 * i + b]) << (8U * b);
    }
    out.words[i] = static_cast<std::int32_t>(bits);
  }
  return ParseCheck::OK;
}

ParseCheck parse_const_shift(std::span<const std::byte> payload, std::uint16_t& out) noexcept {
  if (payload.size() != 4) return ParseCheck::WRONG_SIZE;
  if (load_le16(payload, 0) != 0) return ParseCheck::DEVICE_STATUS;
  const std::uint16_t shift = load_le16(payload, 2);
  if (shift == 0 || shift > 2047) return ParseCheck::OUT_OF_RANGE;
  out = shift;
  return ParseCheck::OK;
}

}  // namespace orthoflow::drivers::kinect
