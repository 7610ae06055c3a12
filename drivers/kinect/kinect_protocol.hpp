#pragma once
/// @file
/// @brief The Kinect v1 camera's control protocol as pure functions over bytes
/// (specs/KINECT_V1.md sections 1, 4 and 5): model detection, GM command framing, RB reply
/// validation, the register scripts that start and stop each stream, and the parsers of the
/// calibration replies. No transport, no clock, no allocation: everything here is tested on byte
/// arrays, and fuzzed (tests/fuzz).
#include <array>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>

#include "drivers/usb/usb_transport.hpp"

namespace orthoflow::drivers::kinect {

inline constexpr std::uint16_t VENDOR_MICROSOFT = 0x045E;
inline constexpr std::uint16_t PID_CAMERA = 0x02AE;      ///< models 1414 and 1473
inline constexpr std::uint16_t PID_CAMERA_K4W = 0x02BF;  ///< Kinect for Windows
inline constexpr std::uint16_t PID_MOTOR = 0x02B0;       ///< model 1414 only
inline constexpr std::uint16_t PID_AUDIO = 0x02AD;       ///< models 1414 and 1473
inline constexpr std::uint16_t BCD_MODEL_1414 = 0x010B;  ///< bcdDevice of a 1414 camera

inline constexpr std::uint8_t EP_VIDEO = 0x81;            ///< isochronous IN: Bayer, UYVY or IR
inline constexpr std::uint8_t EP_DEPTH = 0x82;            ///< isochronous IN: depth
inline constexpr std::size_t ISO_PACKET_FALLBACK = 1920;  ///< 2 x 960 when the size query fails

/// @brief Which Kinect v1 a camera function belongs to (KINECT_V1.md 1).
enum class Model : std::uint8_t { K1414, K1473, K4W };
/// @brief "1414", "1473" or "k4w". @pre none.
[[nodiscard]] const char* to_string(Model model) noexcept;
/// @brief The model of a camera function, or nullopt if @p camera is not a Kinect v1 camera.
/// PID 0x02AE with bcdDevice 0x010B is a 1414; other bcdDevice values are a 1473; 0x02BF is K4W.
[[nodiscard]] std::optional<Model> detect_model(const UsbDeviceInfo& camera) noexcept;

// ---- GM commands and RB replies (KINECT_V1.md 4.1, 4.2) ----------------------------------------

inline constexpr std::size_t HEADER_BYTES = 8;
inline constexpr std::size_t MAX_COMMAND_PAYLOAD = 0x400 - HEADER_BYTES;  ///< 1016 bytes
inline constexpr std::size_t REPLY_BUFFER_BYTES = 512;  ///< wLength of every reply read

/// @brief Opcodes the driver sends (KINECT_V1.md 4.3).
enum class Opcode : std::uint16_t {
  GET_PARAM = 0x02,
  SET_PARAM = 0x03,
  GET_FIXED_PARAMS = 0x04,
  ALGORITHM_PARAMS = 0x16,
  CMOS_REGISTER = 0x95,
};

/// @brief A command frame: 8-byte header plus payload, in a fixed buffer (no heap).
struct CommandFrame {
  std::array<std::byte, HEADER_BYTES + MAX_COMMAND_PAYLOAD> bytes{};
  std::size_t size = 0;  ///< bytes in use
  /// @brief The bytes to send. @pre none.
  [[nodiscard]] std::span<const std::byte> view() const noexcept { return {bytes.data(), size}; }
};

/// @brief Frames command @p opcode with sequence @p tag and @p payload ("GM", length in words).
/// @return nullopt if the payload is odd-sized or longer than 1016 bytes. @note Pure.
[[nodiscard]] std::optional<CommandFrame> encode_command(
    std::uint16_t opcode, std::uint16_t tag, std::span<const std::byte> payload) noexcept;

/// @brief What a reply read returned, in the order libfreenect checks (KINECT_V1.md 4.2).
enum class ReplyCheck : std::uint8_t {
  OK,
  NOT_READY,     ///< 0 or 512 bytes: the device has no reply yet (the 512 is the xHCI quirk)
  TOO_SHORT,     ///< 1..7 bytes
  BAD_MAGIC,     ///< not "RB"
  WRONG_OPCODE,  ///< the opcode is not the one sent
  WRONG_TAG,     ///< the tag is not the one sent
  BAD_LENGTH,    ///< len x 2 differs from the bytes after the header
};
/// @brief Lower-case name. @pre none.
[[nodiscard]] const char* to_string(ReplyCheck check) noexcept;

/// @brief A validated reply: its payload (status word first) views the reply buffer.
struct Reply {
  ReplyCheck check = ReplyCheck::NOT_READY;
  std::span<const std::byte> payload{};  ///< the bytes after the header; valid when check == OK
};
/// @brief Validates @p received (the bytes an IN read returned) as the reply to (@p opcode, @p
/// tag).
/// @note Pure; never reads past received. Untrusted input (fuzzed).
[[nodiscard]] Reply check_reply(std::span<const std::byte> received, std::uint16_t opcode,
                                std::uint16_t tag) noexcept;

// ---- register scripts (KINECT_V1.md 4.4, 5) ----------------------------------------------------

/// @brief One register write (opcode 0x03), or a pause the firmware needs between two writes.
struct RegisterWrite {
  std::uint16_t reg = 0;
  std::uint16_t value = 0;
  std::uint16_t wait_ms = 0;  ///< pause before this write (K4W near mode: 100 ms)
};

/// @brief Depth formats the driver streams.
enum class DepthFormat : std::uint8_t { BITS_11, BITS_10 };
/// @brief Video formats the driver streams.
enum class VideoFormat : std::uint8_t { BAYER, UYVY, IR_10BIT, BAYER_HIGH, IR_HIGH };

/// @brief A fixed list of register writes. @note Static storage; never allocates.
using RegisterScript = std::span<const RegisterWrite>;

/// @brief Depth 640x480 at 30 Hz: 0x105=0, 6=0, 0x12=3 (or 2), 0x13=1, 0x14=0x1E, 6=2, 0x17=0.
[[nodiscard]] RegisterScript depth_start_script(DepthFormat format) noexcept;
/// @brief 6=0.
[[nodiscard]] RegisterScript depth_stop_script() noexcept;
/// @brief The video start script of @p format (Bayer 30 Hz; UYVY 15 Hz; IR 640x488; 1280x1024
/// modes, IR-high with the dummy depth start/stop first).
[[nodiscard]] RegisterScript video_start_script(VideoFormat format) noexcept;
/// @brief 5=0.
[[nodiscard]] RegisterScript video_stop_script() noexcept;
/// @brief K4W near mode on (0x15=7, 100 ms, 0x2EF=0) or off (0x15=0x1E, 100 ms, 0x2EF=0x190).
[[nodiscard]] RegisterScript near_mode_script(bool on) noexcept;

// ---- calibration replies (KINECT_V1.md 5.3) ----------------------------------------------------

/// @brief The zero-plane geometry of the fixed parameters (payload offset 94).
struct ZeroPlane {
  float dcmos_emitter_dist_cm = 7.5F;
  float dcmos_rcmos_dist_cm = 2.4F;
  float reference_distance_mm = 120.0F;
  float reference_pixel_size_mm = 0.1042F;
};
/// @brief Padding info (algorithm parameter 0x41).
struct PadInfo {
  std::uint16_t start_lines = 0;
  std::uint16_t end_lines = 0;
  std::uint16_t cropping_lines = 0;
};
/// @brief The 29 registration words (algorithm parameter 0x40), in the device's order.
struct RegInfo {
  std::array<std::int32_t, 29> words{};
};
/// @brief Names of RegInfo::words, e.g. "dx_center", "ax" (fakenect's device.json keys).
[[nodiscard]] const char* reg_info_name(std::size_t index) noexcept;

/// @brief Everything the calibration reads return.
struct Calibration {
  ZeroPlane zero_plane{};
  PadInfo pad{};
  RegInfo reg{};
  std::uint16_t const_shift = 200;
  float reported_rcmos_dist_cm = 2.3F;  ///< what the device said before the 2.4 cm override
};

/// @brief Why a calibration payload was refused.
enum class ParseCheck : std::uint8_t { OK, WRONG_SIZE, DEVICE_STATUS, NOT_FINITE, OUT_OF_RANGE };
/// @brief Lower-case name. @pre none.
[[nodiscard]] const char* to_string(ParseCheck check) noexcept;

/// @brief Reads the zero plane from a fixed-parameters payload (322 bytes on 1414, 334 on the
/// others; @p model picks which size is accepted). Overrides dcmos_rcmos_dist with 2.4 cm as
/// libfreenect does; the reported value goes to @p reported_rcmos. Refuses non-finite or
/// implausible geometry (pixel size outside 0.05..0.2 mm, distances outside 50..500 mm,
/// baseline outside 1..20 cm). @note Pure.
[[nodiscard]] ParseCheck parse_fixed_params(std::span<const std::byte> payload, Model model,
                                            ZeroPlane& out, float& reported_rcmos) noexcept;
/// @brief Padding info from an 8-byte payload.
[[nodiscard]] ParseCheck parse_pad_info(std::span<const std::byte> payload, PadInfo& out) noexcept;
/// @brief Registration words from a 118-byte payload.
[[nodiscard]] ParseCheck parse_reg_info(std::span<const std::byte> payload, RegInfo& out) noexcept;
/// @brief Const shift from a 4-byte payload (refused outside 1..2047).
[[nodiscard]] ParseCheck parse_const_shift(std::span<const std::byte> payload,
                                           std::uint16_t& out) noexcept;

/// @brief Little-endian u16 at @p offset. @pre offset + 2 <= bytes.size().
[[nodiscard]] inline std::uint16_t load_le16(std::span<const std::byte> bytes,
                                             std::size_t offset) noexcept {
  return static_cast<std::uint16_t>(std::to_integer<unsigned>(bytes[offset]) |
                                    (std::to_integer<unsigned>(bytes[offset + 1]) << 8U));
}
/// @brief Stores @p value little-endian at @p offset. @pre offset + 2 <= bytes.size().
inline void store_le16(std::span<std::byte> bytes, std::size_t offset,
                       std::uint16_t value) noexcept {
  bytes[offset] = static_cast<std::byte>(value & 0xFFU);
  bytes[offset + 1] = static_cast<std::byte>(value >> 8U);
}

}  // namespace orthoflow::drivers::kinect
