#pragma once
/// @file
/// @brief The Kinova JACO's USB protocol as pure functions over bytes (specs/JACO.md sections 3-7
/// and 10): the 64-byte packet codec, the command ids, the payload layouts (trajectory point,
/// joystick state, sensor info, client configuration, firmware versions, arm status), reply
/// validation and the home/retract virtual-button table. No transport, no clock, no allocation:
/// everything here is tested on byte arrays, and the reply parsers are fuzzed (tests/fuzz).
///
/// Every parser treats the arm's bytes as untrusted (STYLE rule 16): a short packet, a wrong
/// command id, a float that is NaN or infinite, a string without its NUL all come back as a
/// PacketCheck, never as a value.
#include <array>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>
#include <string_view>

#include "core/fixed_text.hpp"
#include "drivers/usb/usb_transport.hpp"

namespace orthoflow::drivers::jaco {

inline constexpr std::uint16_t VENDOR_KINOVA = 0x22CD;
inline constexpr std::uint16_t PID_JACO = 0x0000;
inline constexpr std::uint8_t INTERFACE = 0;
inline constexpr std::uint8_t EP_OUT = 0x02;  ///< interrupt OUT
inline constexpr std::uint8_t EP_IN = 0x82;   ///< interrupt IN
inline constexpr std::size_t PACKET_BYTES = 64;
inline constexpr std::size_t HEADER_BYTES = 8;
inline constexpr std::size_t BODY_BYTES = PACKET_BYTES - HEADER_BYTES;  ///< 56 = 14 floats
inline constexpr std::size_t BODY_FLOATS = BODY_BYTES / 4;
inline constexpr std::size_t JOINTS = 6;
inline constexpr std::size_t FINGERS = 3;
inline constexpr std::size_t CLIENT_INFO_SLICES = 55;      ///< command 1 exchanges (2 decoded)
inline constexpr std::size_t ARM_INFO_SLICES = 19;         ///< command 200 exchanges (slice 2 used)
inline constexpr std::size_t TRAJECTORY_FIFO = 2000;       ///< points the arm queues (JACO.md 9)
inline constexpr std::int64_t ARM_PERIOD_NS = 10'000'000;  ///< the DSP's 100 Hz loop

/// @brief The command ids of JACO.md 5 (libkindrv's names).
enum class Command : std::uint16_t {
  GET_CLIENT_INFO = 1,
  GET_ANG_POS = 15,
  GET_FIRMWARE = 36,
  SET_CONTROL_ANGULAR = 47,
  SET_CONTROL_CARTESIAN = 49,
  START_FORCE_CONTROL = 57,
  STOP_FORCE_CONTROL = 58,
  GET_ARM_STATUS = 62,
  GET_CART_INFO = 104,
  GET_ANG_INFO = 105,
  GET_CART_COMMAND = 106,
  GET_ANG_COMMAND = 107,
  GET_CART_FORCE = 108,
  GET_ANG_FORCE = 109,
  GET_ANG_CURRENT = 110,
  GET_SENSOR_INFO = 111,
  GET_ANG_CURRENT_MOTOR = 113,
  GET_ANG_VEL = 114,
  GET_ARM_INFO = 200,
  ERASE_TRAJECTORIES = 301,
  START_API_CONTROL = 302,
  STOP_API_CONTROL = 303,
  JOYSTICK = 305,
  SEND_BASIC_TRAJECTORY = 308,
};
/// @brief libkindrv's name in lower case, e.g. "get_ang_pos"; "unknown" otherwise. @pre none.
[[nodiscard]] const char* to_string(Command command) noexcept;
/// @brief True if @p id is one of the commands above. @pre none.
[[nodiscard]] bool is_known_command(std::uint16_t id) noexcept;

/// @brief One packet as bytes on the wire.
using Packet = std::array<std::byte, PACKET_BYTES>;

/// @brief The four little-endian u16 of a packet's header (JACO.md 3).
struct PacketHeader {
  std::uint16_t id_packet = 1;        ///< 1-based slice index
  std::uint16_t packet_quantity = 1;  ///< libkindrv always sends 1
  std::uint16_t command_id = 0;
  std::uint16_t command_size = 0;  ///< data bytes of the command
};

/// @brief Why a packet was refused.
enum class PacketCheck : std::uint8_t {
  OK,
  SHORT,          ///< fewer than 64 bytes
  WRONG_COMMAND,  ///< reply command_id differs from the request's
  NOT_FINITE,     ///< a float field is NaN or infinite
  BAD_STRING,     ///< a client-info string lacks its NUL or holds non-printable bytes
  BAD_VALUE,      ///< an enumeration or flag outside its documented range
};
/// @brief Lower-case name, e.g. "wrong_command". @pre none.
[[nodiscard]] const char* to_string(PacketCheck check) noexcept;

/// @brief A zeroed packet with @p header. @pre none.
[[nodiscard]] Packet make_packet(const PacketHeader& header) noexcept;
/// @brief A "get" request for @p command (command_size 1) for slice @p id_packet (1-based).
[[nodiscard]] Packet make_request(Command command, std::uint16_t id_packet = 1) noexcept;
/// @brief An argument-less set command: start/stop API, erase, control modes (JACO.md 3).
[[nodiscard]] Packet make_plain_command(Command command) noexcept;
/// @brief The header of @p packet. @pre none.
[[nodiscard]] PacketHeader read_header(std::span<const std::byte, PACKET_BYTES> packet) noexcept;
/// @brief Float @p index (0..13) of the body. @pre index < BODY_FLOATS.
[[nodiscard]] float body_float(std::span<const std::byte, PACKET_BYTES> packet,
                               std::size_t index) noexcept;
/// @brief Writes float @p index of the body. @pre index < BODY_FLOATS.
void set_body_float(Packet& packet, std::size_t index, float value) noexcept;
/// @brief Body bytes [offset, offset + 4) as a little-endian i32 / u32. @pre offset + 4 <= 56.
[[nodiscard]] std::int32_t body_i32(std::span<const std::byte, PACKET_BYTES> packet,
                                    std::size_t offset) noexcept;
void set_body_i32(Packet& packet, std::size_t offset, std::int32_t value) noexcept;
[[nodiscard]] std::uint32_t body_u32(std::span<const std::byte, PACKET_BYTES> packet,
                                     std::size_t offset) noexcept;
void set_body_u32(Packet& packet, std::size_t offset, std::uint32_t value) noexcept;

/// @brief Checks a reply to @p request: all 64 bytes and the same command id (JACO.md 4).
[[nodiscard]] PacketCheck check_reply(std::span<const std::byte> reply, Command request) noexcept;

// ---- Payloads (JACO.md 6, 7) ------------------------------------------------------------------

/// @brief JACO.md 7.1.
enum class PositionType : std::int32_t {
  NO_MOVEMENT = 0,
  CARTESIAN_POSITION = 1,
  ANGULAR_POSITION = 2,
  CARTESIAN_VELOCITY = 7,
  ANGULAR_VELOCITY = 8,
  TIME_DELAY = 12,
};
/// @brief JACO.md 7.2.
enum class HandMode : std::int32_t { NO_MOVEMENT = 0, POSITION = 1, VELOCITY = 2 };

/// @brief JACO.md 7.3: where the arm is in its home/retract state machine.
enum class ArmState : std::int32_t {
  NORMAL_TO_READY = 0,
  READY_STANDBY = 1,  ///< at HOME
  READY_TO_RETRACT = 2,
  RETRACT_STANDBY = 3,  ///< retracted
  RETRACT_TO_READY = 4,
  NORMAL = 5,
  NOINIT = 6,
  ERROR = 25000,
};
/// @brief Lower-case name, e.g. "ready_standby". @pre none.
[[nodiscard]] const char* to_string(ArmState state) noexcept;
/// @brief The state for a raw int32, or nullopt for a value outside JACO.md 7.3. @pre none.
[[nodiscard]] std::optional<ArmState> arm_state_from(std::int32_t raw) noexcept;

/// @brief JACO.md 6.1: the 48-byte basic trajectory point (command 308).
struct TrajectoryPoint {
  std::array<float, JOINTS> target{};  ///< joints in deg, or x, y, z (m) and theta x, y, z (rad)
  std::array<float, FINGERS> fingers{};
  float delay_s = 0.0F;
  HandMode hand_mode = HandMode::POSITION;
  PositionType type = PositionType::ANGULAR_POSITION;
};
/// @brief The packet of @p point. @pre Finite fields (the safety layer checks before encoding).
[[nodiscard]] Packet encode_trajectory(const TrajectoryPoint& point) noexcept;
/// @brief The point in a 308 packet (the simulator's side). @return NOT_FINITE, BAD_VALUE.
[[nodiscard]] PacketCheck decode_trajectory(std::span<const std::byte, PACKET_BYTES> packet,
                                            TrajectoryPoint& out) noexcept;

/// @brief JACO.md 6.2: the 56-byte joystick state (command 305).
struct JoystickState {
  std::array<std::uint16_t, 16> buttons{};  ///< 1 pressed; index 2 is HOME/RETRACT
  std::array<float, 6> axes{};              ///< stick axes, clamped to [-1, 1] by the driver
  /// @brief True if nothing is pressed or deflected: the release packet. @pre none.
  [[nodiscard]] bool is_release() const noexcept;
};
inline constexpr std::size_t HOME_BUTTON = 2;
/// @brief The packet of @p state (all-zero body for a release). @pre Finite axes.
[[nodiscard]] Packet encode_joystick(const JoystickState& state) noexcept;
/// @brief The state in a 305 packet. @return NOT_FINITE, BAD_VALUE (a button other than 0/1).
[[nodiscard]] PacketCheck decode_joystick(std::span<const std::byte, PACKET_BYTES> packet,
                                          JoystickState& out) noexcept;
/// @brief A press of the HOME/RETRACT button. @pre none.
[[nodiscard]] JoystickState home_button_press() noexcept;

/// @brief Nine floats of a 15/104/105-114 reply: six joint or pose values and three fingers.
struct NineFloats {
  std::array<float, JOINTS> values{};
  std::array<float, FINGERS> fingers{};
};
/// @brief Parses a position/velocity/force/current reply. @return NOT_FINITE on a bad float.
[[nodiscard]] PacketCheck parse_nine(std::span<const std::byte, PACKET_BYTES> reply,
                                     NineFloats& out) noexcept;
/// @brief The reply packet of @p values for @p command (the simulator's side). @pre none.
[[nodiscard]] Packet encode_nine(Command command, const NineFloats& values) noexcept;

/// @brief JACO.md 6.3: the 14 floats of GET_SENSOR_INFO.
struct SensorInfo {
  float voltage_v = 0.0F;
  float current_a = 0.0F;
  std::array<float, 3> accel_g{};
  std::array<float, JOINTS> actuator_temp_c{};
  std::array<float, FINGERS> finger_temp_c{};
};
[[nodiscard]] PacketCheck parse_sensor_info(std::span<const std::byte, PACKET_BYTES> reply,
                                            SensorInfo& out) noexcept;
[[nodiscard]] Packet encode_sensor_info(const SensorInfo& info) noexcept;

/// @brief JACO.md 6.5: firmware versions (command 36).
struct FirmwareVersion {
  std::uint8_t major = 0, minor = 0, patch = 0;
  /// @brief DSP >= 5 changes the joystick axes and the status command (JACO.md 6.2, 6.6).
  [[nodiscard]] bool dsp5() const noexcept { return major >= 5; }
};
struct Firmware {
  FirmwareVersion dsp{};
  std::array<FirmwareVersion, JOINTS> actuators{};
  std::array<FirmwareVersion, FINGERS> fingers{};
};
[[nodiscard]] FirmwareVersion firmware_word(std::uint32_t word) noexcept;
[[nodiscard]] PacketCheck parse_firmware(std::span<const std::byte, PACKET_BYTES> reply,
                                         Firmware& out) noexcept;
[[nodiscard]] Packet encode_firmware(const Firmware& firmware) noexcept;

/// @brief JACO.md 6.4: the strings of client-info slices 1 and 2 (112 bytes).
inline constexpr std::size_t CLIENT_STRING_BYTES = 20;
struct ClientInfo {
  core::FixedText<CLIENT_STRING_BYTES> client_id{}, name{}, organisation{}, serial{}, model{};
};
/// @brief Parses the 112 bytes of slices 1 and 2. @return BAD_STRING on a missing NUL or a
/// non-printable byte. @pre slices.size() == 2 * BODY_BYTES.
[[nodiscard]] PacketCheck parse_client_info(std::span<const std::byte> slices,
                                            ClientInfo& out) noexcept;
/// @brief The 112 bytes of @p info (the simulator's side). @pre Strings shorter than 20 bytes.
void encode_client_info(const ClientInfo& info, std::span<std::byte, 2 * BODY_BYTES> out) noexcept;

/// @brief JACO.md 6.6: the DSP >= 5 arm status (command 62).
struct ArmStatus {
  ArmState state = ArmState::NOINIT;
  std::array<std::uint8_t, FINGERS> finger_init{};
  std::uint8_t api_control = 0;
  std::uint8_t force_control = 0;
  std::uint8_t current_limitation = 0;
  std::uint8_t torque_sensors = 0;
};
[[nodiscard]] PacketCheck parse_arm_status(std::span<const std::byte, PACKET_BYTES> reply,
                                           ArmStatus& out) noexcept;
[[nodiscard]] Packet encode_arm_status(const ArmStatus& status) noexcept;
/// @brief Command 200's slice 2: the retract mode at body bytes 52-55. @return BAD_VALUE.
[[nodiscard]] PacketCheck parse_arm_info_slice2(std::span<const std::byte, PACKET_BYTES> reply,
                                                ArmState& out) noexcept;
inline constexpr std::size_t ARM_INFO_STATE_OFFSET = 52;

// ---- Models (JACO.md 8) -----------------------------------------------------------------------

/// @brief JACO v1 fingers run 0..~60, JACO2 fingers 0..~6800 motor turns.
enum class Model : std::uint8_t { JACO_V1, JACO2 };
[[nodiscard]] const char* to_string(Model model) noexcept;
/// @brief The model named by the client-info model string ("JACO2...", "Jaco v2", "j2..." is a
/// JACO2; anything else a v1), falling back on the DSP major (6 and up are JACO2 firmware) [I].
[[nodiscard]] Model detect_model(const ClientInfo& info, const Firmware& firmware) noexcept;
/// @brief Finger position for fully closed on @p model (open is 0). @pre none.
[[nodiscard]] float finger_closed(Model model) noexcept;

// ---- HOME / RETRACT through the virtual button (JACO.md 10.1) ---------------------------------

enum class ArmGoal : std::uint8_t { HOME, RETRACT };
/// @brief What to do next: press (button 2 = 1), release, wait (keep the button as it is and poll),
/// done (release if pressed, the goal holds), or refuse (RETRACT from NORMAL / NOINIT: home first).
enum class ButtonAction : std::uint8_t { PRESS, RELEASE, WAIT, DONE, REFUSE };
[[nodiscard]] const char* to_string(ButtonAction action) noexcept;
/// @brief The virtual-button step for @p goal from @p state with the button now @p pressed.
/// Pure and table-driven (JACO.md 10.1): a reversing state (moving away from the goal) is answered
/// with release then press; a state moving toward the goal is waited on while pressed.
[[nodiscard]] ButtonAction next_button_action(ArmState state, ArmGoal goal, bool pressed) noexcept;
/// @brief The state @p goal ends in: READY_STANDBY or RETRACT_STANDBY. @pre none.
[[nodiscard]] ArmState goal_state(ArmGoal goal) noexcept;

}  // namespace orthoflow::drivers::jaco
