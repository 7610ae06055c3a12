#pragma once
// Helpers for the simulated-Kinect tests: they speak to SimUsbTransport only through the
// UsbTransport interface, with hand-built bytes (no drivers/kinect_* code).
#include <gtest/gtest.h>

#include <cstddef>
#include <cstdint>
#include <vector>

#include "simulation/devices/sim_usb_transport.hpp"

namespace orthoflow::simulation::test {

using drivers::UsbControlSetup;
using drivers::UsbDeviceHandle;
using drivers::UsbDeviceInfo;
using drivers::UsbError;
using drivers::UsbIsoConfig;
using drivers::UsbPacketStatus;
using drivers::UsbTimeout;

inline constexpr UsbTimeout TIMEOUT_500MS{500};
inline constexpr std::size_t PIXELS = 640 * 480;

/// A cheap deterministic depth pattern covering every 11-bit value, different per frame.
inline void pattern_depth(std::uint64_t frame, std::span<std::uint16_t> raw) {
  for (std::size_t i = 0; i < raw.size(); ++i)
    raw[i] = static_cast<std::uint16_t>((i * 7 + frame * 13) % 2048);
}

inline void pattern_bayer(std::uint64_t frame, std::span<std::uint8_t> bayer) {
  for (std::size_t i = 0; i < bayer.size(); ++i)
    bayer[i] = static_cast<std::uint8_t>((i * 3 + frame) & 0xFFU);
}

inline SimKinectConfig cheap_config(KinectModel model = KinectModel::K1414) {
  SimKinectConfig c;
  c.model = model;
  c.depth_source = pattern_depth;
  c.bayer_source = pattern_bayer;
  c.ir_source = [](std::uint64_t, std::span<std::uint16_t> ir) {
    for (std::size_t i = 0; i < ir.size(); ++i) ir[i] = static_cast<std::uint16_t>(i % 1024);
  };
  return c;
}

/// One GM exchange's reply bytes (header included), polling past 0- and 512-byte replies.
std::vector<std::uint8_t> gm_exchange(drivers::UsbTransport& usb, const UsbDeviceHandle& cam,
                                      std::uint16_t cmd, std::uint16_t tag,
                                      const std::vector<std::uint16_t>& words);
/// Sends only the GM command; returns the control result.
Result<std::size_t, UsbError> gm_send(drivers::UsbTransport& usb, const UsbDeviceHandle& cam,
                                      std::uint16_t cmd, std::uint16_t tag,
                                      const std::vector<std::uint16_t>& words);
/// One IN read of the reply buffer (wLength 512).
Result<std::size_t, UsbError> gm_read(drivers::UsbTransport& usb, const UsbDeviceHandle& cam,
                                      std::vector<std::uint8_t>& reply);
/// SET_PARAM reg <- value; expects status 0.
void write_reg(drivers::UsbTransport& usb, const UsbDeviceHandle& cam, std::uint16_t& tag,
               std::uint16_t reg, std::uint16_t value);

inline std::uint16_t le16(const std::vector<std::uint8_t>& b, std::size_t at) {
  return static_cast<std::uint16_t>(b[at] | (b[at + 1] << 8));
}

/// A plugged Kinect with its camera opened, kernel driver detached and interface 0 claimed.
struct Rig {
  explicit Rig(SimKinectConfig config = cheap_config());
  SimUsbTransport usb;
  std::size_t index = 0;
  UsbDeviceHandle cam;
  std::uint16_t tag = 0;
  [[nodiscard]] SimKinectDevice& device() { return usb.kinect(index); }
  /// KINECT_V1.md 5.1 with 0x12 <- format.
  void start_depth(std::uint16_t format = 3);
};

/// Every packet a stream delivered.
struct Packet {
  std::vector<std::uint8_t> bytes;
  UsbPacketStatus status = UsbPacketStatus::COMPLETED;
};
struct Collector {
  std::vector<Packet> packets;  // non-empty or failed packets
  std::size_t empty = 0;        // zero-length COMPLETED packets
  drivers::UsbIsoCallback callback();
};

/// Indices into packets of each whole frame: SOF ... EOF of one stream nibble, in order.
std::vector<std::vector<std::size_t>> frames_of(const std::vector<Packet>& packets);
/// The frame's payload bytes, concatenated.
std::vector<std::uint8_t> payload_of(const std::vector<Packet>& packets,
                                     const std::vector<std::size_t>& frame);
/// Naive MSB-first bit reader: value @p k of width @p bits.
std::uint16_t read_bits(const std::vector<std::uint8_t>& stream, std::size_t k, unsigned bits);

}  // namespace orthoflow::simulation::test
