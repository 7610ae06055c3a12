// Helpers for the simulated-Kinect tests (hand-built GM frames, a packet collector, a bit reader).
#include "sim_kinect_test_support.hpp"

#include <cstring>

namespace orthoflow::simulation::test {

Result<std::size_t, UsbError> gm_send(drivers::UsbTransport& usb, const UsbDeviceHandle& cam,
                                      std::uint16_t cmd, std::uint16_t tag,
                                      const std::vector<std::uint16_t>& words) {
  std::vector<std::byte> out(8 + 2 * words.size());
  const auto put = [&](std::size_t at, std::uint16_t v) {
    out[at] = std::byte{static_cast<std::uint8_t>(v & 0xFFU)};
    out[at + 1] = std::byte{static_cast<std::uint8_t>(v >> 8)};
  };
  out[0] = std::byte{0x47};
  out[1] = std::byte{0x4D};
  put(2, static_cast<std::uint16_t>(words.size()));
  put(4, cmd);
  put(6, tag);
  for (std::size_t i = 0; i < words.size(); ++i) put(8 + 2 * i, words[i]);
  return usb.control(cam, UsbControlSetup{0x40, 0, 0, 0}, out, TIMEOUT_500MS);
}

Result<std::size_t, UsbError> gm_read(drivers::UsbTransport& usb, const UsbDeviceHandle& cam,
                                      std::vector<std::uint8_t>& reply) {
  std::vector<std::byte> in(512);
  auto n_result = usb.control(cam, UsbControlSetup{0xC0, 0, 0, 0}, in, TIMEOUT_500MS);
  if (n_result) {
    reply.resize(*n_result);
    if (*n_result > 0) std::memcpy(reply.data(), in.data(), *n_result);
  }
  return n_result;
}

std::vector<std::uint8_t> gm_exchange(drivers::UsbTransport& usb, const UsbDeviceHandle& cam,
                                      std::uint16_t cmd, std::uint16_t tag,
                                      const std::vector<std::uint16_t>& words) {
  EXPECT_TRUE(gm_send(usb, cam, cmd, tag, words).has_value());
  std::vector<std::uint8_t> reply;
  for (int poll = 0; poll < 100; ++poll) {
    auto n_result = gm_read(usb, cam, reply);
    EXPECT_TRUE(n_result.has_value());
    if (!n_result || (*n_result != 0 && *n_result != 512)) break;
  }
  return reply;
}

void write_reg(drivers::UsbTransport& usb, const UsbDeviceHandle& cam, std::uint16_t& tag,
               std::uint16_t reg, std::uint16_t value) {
  const auto reply = gm_exchange(usb, cam, 0x03, tag, {reg, value});
  ASSERT_EQ(reply.size(), 10U);
  EXPECT_EQ(le16(reply, 6), tag);
  EXPECT_EQ(le16(reply, 8), 0U) << "status of reg " << reg;
  ++tag;
}

Rig::Rig(SimKinectConfig config) {
  index = usb.add_kinect(std::move(config));
  auto found = usb.enumerate(KINECT_VENDOR, KINECT_CAMERA_PID);
  if (!found || found->empty()) found = usb.enumerate(KINECT_VENDOR, KINECT_K4W_CAMERA_PID);
  EXPECT_TRUE(found && found->size() == 1);
  auto cam_result = usb.open(found->front());
  EXPECT_TRUE(cam_result.has_value());
  cam = std::move(cam_result).value();
  EXPECT_TRUE(usb.detach_kernel_driver(cam, 0).has_value());
  EXPECT_TRUE(usb.claim_interface(cam, 0).has_value());
}

void Rig::start_depth(std::uint16_t format) {
  const std::pair<std::uint16_t, std::uint16_t> script[] = {
      {0x105, 0}, {0x06, 0}, {0x12, format}, {0x13, 1}, {0x14, 0x1E}, {0x06, 2}, {0x17, 0}};
  for (const auto& [reg, value] : script) write_reg(usb, cam, tag, reg, value);
}

drivers::UsbIsoCallback Collector::callback() {
  return [this](std::span<const std::byte> bytes, std::size_t length, UsbPacketStatus status) {
    EXPECT_EQ(bytes.size(), length);
    if (length == 0 && status == UsbPacketStatus::COMPLETED) {
      ++empty;
      return;
    }
    Packet p;
    p.status = status;
    p.bytes.resize(length);
    if (length > 0) std::memcpy(p.bytes.data(), bytes.data(), length);
    packets.push_back(std::move(p));
  };
}

std::vector<std::vector<std::size_t>> frames_of(const std::vector<Packet>& packets) {
  std::vector<std::vector<std::size_t>> frames;
  std::vector<std::size_t> current;
  bool open = false;
  for (std::size_t i = 0; i < packets.size(); ++i) {
    const auto& b = packets[i].bytes;
    if (b.size() < 12) continue;
    const unsigned kind = b[3] & 0x0FU;
    if (kind == 1) {
      current.clear();
      open = true;
    }
    if (!open) continue;
    current.push_back(i);
    if (kind == 5) {
      frames.push_back(current);
      open = false;
    }
  }
  return frames;
}

std::vector<std::uint8_t> payload_of(const std::vector<Packet>& packets,
                                     const std::vector<std::size_t>& frame) {
  std::vector<std::uint8_t> out;
  for (const std::size_t i : frame)
    out.insert(out.end(), packets[i].bytes.begin() + 12, packets[i].bytes.end());
  return out;
}

std::uint16_t read_bits(const std::vector<std::uint8_t>& stream, std::size_t k, unsigned bits) {
  std::uint16_t v = 0;
  for (unsigned b = 0; b < bits; ++b) {
    const std::size_t bit = k * bits + b;
    v = static_cast<std::uint16_t>((v << 1) | ((stream[bit / 8] >> (7 - bit % 8)) & 1U));
  }
  return v;
}

}  // namespace orthoflow::simulation::test
