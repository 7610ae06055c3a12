// Fuzzes the Kinect v1 driver's parsers of device and recording bytes: the isochronous frame
// assembler (any sequence of packets of any length and content), the RB reply check, the
// calibration payload parsers, and the fakenect recording's device.json and depth records. No input
// may crash, hang, leak or hit UB, and every delivered frame must keep the assembler's invariants
// (whole size, consistent packet map, "complete" only when every slot is).
#include <cstdint>
#include <span>
#include <string_view>
#include <vector>

#include "drivers/kinect/kinect_assembler.hpp"
#include "drivers/kinect/kinect_protocol.hpp"
#include "formats/fakenect.hpp"
#include "graphs/nodes/fakenect_calibration.hpp"

namespace kinect = orthoflow::drivers::kinect;

namespace {

void check_frame(const kinect::AssembledFrame& f, const kinect::StreamGeometry& g) {
  if (f.bytes.size() != g.frame_bytes || f.packet_present.size() != g.packets) __builtin_trap();
  std::size_t present = 0;
  for (const std::uint8_t p : f.packet_present) present += p != 0 ? 1U : 0U;
  if (present != f.packets_present || f.complete != (present == g.packets)) __builtin_trap();
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::span<const std::uint8_t> in(data, size);
  if (in.empty()) return 0;
  const std::uint8_t mode = in[0] % 5;
  const auto rest = in.subspan(1);
  if (mode == 0) {
    // Packets: [len_hi len_lo] [len bytes] ...; a short stream of small frames plus a depth one.
    const auto depth = kinect::depth_geometry(11);
    const auto video = kinect::video_geometry(4 * 1908 + 12);
    kinect::FrameAssembler a(depth,
                             [&](const kinect::AssembledFrame& f) { check_frame(f, depth); });
    kinect::FrameAssembler b(video,
                             [&](const kinect::AssembledFrame& f) { check_frame(f, video); });
    std::size_t at = 0;
    while (at + 2 <= rest.size()) {
      const std::size_t len = (std::size_t{rest[at]} << 8U | rest[at + 1]) % 2048;
      at += 2;
      const auto packet = rest.subspan(at, std::min(len, rest.size() - at));
      a.push(packet, 0);
      b.push(packet, 0);
      at += packet.size();
    }
    const auto& s = a.stats();
    if (s.frames_complete + s.frames_incomplete > s.packets) __builtin_trap();
    return 0;
  }
  const auto bytes = std::as_bytes(rest);
  if (mode == 1) {
    if (rest.size() < 4) return 0;
    const auto opcode = static_cast<std::uint16_t>(rest[0] | rest[1] << 8U);
    const auto tag = static_cast<std::uint16_t>(rest[2] | rest[3] << 8U);
    const kinect::Reply r = kinect::check_reply(bytes.subspan(4), opcode, tag);
    if (r.check == kinect::ReplyCheck::OK &&
        r.payload.size() + kinect::HEADER_BYTES != bytes.size() - 4)
      __builtin_trap();
    return 0;
  }
  if (mode == 3) {  // fakenect's device.json
    const std::string_view text(reinterpret_cast<const char*>(rest.data()), rest.size());
    auto c = orthoflow::graphs::parse_fakenect_device(text, "fuzz");
    if (!c && c.error().message.empty()) __builtin_trap();
    return 0;
  }
  if (mode == 4) {  // a fakenect depth record (its header, size and values)
    static std::vector<std::uint16_t> raw(orthoflow::formats::FAKENECT_PIXELS);
    const std::span<const char> text(reinterpret_cast<const char*>(rest.data()), rest.size());
    auto r = orthoflow::formats::parse_fakenect_depth(text, "fuzz", raw);
    if (!r && r.error().message.empty()) __builtin_trap();
    return 0;
  }
  kinect::ZeroPlane zp;
  float reported = 0;
  (void)kinect::parse_fixed_params(bytes, kinect::Model::K1414, zp, reported);
  (void)kinect::parse_fixed_params(bytes, kinect::Model::K1473, zp, reported);
  kinect::PadInfo pad;
  (void)kinect::parse_pad_info(bytes, pad);
  kinect::RegInfo reg;
  (void)kinect::parse_reg_info(bytes, reg);
  std::uint16_t shift = 0;
  (void)kinect::parse_const_shift(bytes, shift);
  return 0;
}
