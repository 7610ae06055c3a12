#include "formats/fakenect.hpp"

#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstring>

#include "formats/file_bytes.hpp"

namespace orthoflow::formats {

namespace {

constexpr std::string_view DEPTH_HEADER = "P5 640 480 65535\n";
constexpr std::string_view RGB_HEADER = "P6 640 480 255\n";

IoError bad(IoError::Code code, const std::string& name, const std::string& what) {
  return IoError{code, name + ": " + what};
}

Result<void, IoError> write_bytes(const std::filesystem::path& path, std::string_view header,
                                  const void* data, std::size_t size) {
  std::string bytes(header);
  bytes.append(static_cast<const char*>(data), size);
  return write_file_atomically(path, bytes);
}

Result<std::span<const char>, IoError> body_after(std::span<const char> bytes,
                                                  std::string_view header, std::size_t body,
                                                  const std::string& name) {
  if (bytes.size() < header.size() || std::string_view(bytes.data(), header.size()) != header) {
    return err(bad(IoError::Code::BAD_HEADER, name,
                   "not a fakenect record: the header must be '" +
                       std::string(header.substr(0, header.size() - 1)) + "'"));
  }
  const std::size_t have = bytes.size() - header.size();
  if (have != body) {
    return err(
        bad(have < body ? IoError::Code::TRUNCATED : IoError::Code::SIZE_MISMATCH, name,
            std::to_string(have) + " data bytes, a 640x480 record has " + std::to_string(body)));
  }
  return bytes.subspan(header.size());
}

}  // namespace

std::string fakenect_name(char kind, double host_seconds, std::uint32_t device_ticks) {
  const char* ext = kind == 'd' ? "pgm" : kind == 'r' ? "ppm" : "dump";
  char name[96];
  std::snprintf(name, sizeof name, "%c-%.6f-%u.%s", kind, host_seconds, device_ticks, ext);
  return name;
}

Result<std::vector<FakenectEntry>, IoError> read_fakenect_index(const std::filesystem::path& dir) {
  const auto path = dir / "INDEX.txt";
  auto bytes = read_file_bytes(path, std::size_t{64} << 20);
  if (!bytes) return err(bytes.error());
  std::vector<FakenectEntry> entries;
  const std::string_view text(bytes->data(), bytes->size());
  std::size_t line_no = 0, at = 0;
  while (at < text.size()) {
    const std::size_t end = std::min(text.find('\n', at), text.size());
    std::string_view line = text.substr(at, end - at);
    at = end + 1;
    ++line_no;
    if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
    if (line.empty()) continue;
    const auto where = path.string() + ": line " + std::to_string(line_no);
    // <kind>-<seconds>-<ticks>.<ext>, kind in d r a
    FakenectEntry e;
    e.file = std::string(line);
    const std::size_t d1 = line.find('-'), d2 = line.find('-', d1 + 1), dot = line.rfind('.');
    if (line.size() < 7 || d1 != 1 || d2 == std::string_view::npos ||
        dot == std::string_view::npos || dot < d2 || line.find('/') != std::string_view::npos) {
      return err(IoError{IoError::Code::BAD_HEADER,
                         where + ": '" + e.file + "' is not <d|r|a>-<seconds>-<timestamp>.<ext>"});
    }
    e.kind = line[0];
    const std::string_view ext = line.substr(dot + 1);
    const bool ext_ok = (e.kind == 'd' && ext == "pgm") || (e.kind == 'r' && ext == "ppm") ||
                        (e.kind == 'a' && ext == "dump");
    const std::string seconds(line.substr(d1 + 1, d2 - d1 - 1));
    char* seconds_end = nullptr;
    e.host_seconds = std::strtod(seconds.c_str(), &seconds_end);
    const auto ticks = line.substr(d2 + 1, dot - d2 - 1);
    const auto parsed = std::from_chars(ticks.data(), ticks.data() + ticks.size(), e.device_ticks);
    if (!ext_ok || seconds.empty() || seconds_end != seconds.c_str() + seconds.size() ||
        !std::isfinite(e.host_seconds) || parsed.ec != std::errc() ||
        parsed.ptr != ticks.data() + ticks.size()) {
      return err(IoError{IoError::Code::BAD_NUMBER,
                         where + ": '" + e.file + "': kind, time, timestamp or extension"});
    }
    entries.push_back(std::move(e));
  }
  if (entries.empty()) return err(IoError{IoError::Code::TRUNCATED, path.string() + ": empty"});
  return entries;
}

Result<void, IoError> write_fakenect_depth(const std::filesystem::path& path,
                                           std::span<const std::uint16_t> raw) {
  if (raw.size() != FAKENECT_PIXELS)
    return err(bad(IoError::Code::SIZE_MISMATCH, path.string(), "not 640x480"));
  for (const std::uint16_t v : raw) {
    if (v > 2047)
      return err(bad(IoError::Code::BAD_NUMBER, path.string(),
                     "value " + std::to_string(v) + " is not an 11-bit disparity"));
  }
  return write_bytes(path, DEPTH_HEADER, raw.data(), raw.size_bytes());  // host order, as fakenect
}

Result<void, IoError> parse_fakenect_depth(std::span<const char> bytes, const std::string& name,
                                           std::span<std::uint16_t> raw) {
  auto body = body_after(bytes, DEPTH_HEADER, FAKENECT_PIXELS * 2, name);
  if (!body) return err(body.error());
  std::memcpy(raw.data(), body->data(), FAKENECT_PIXELS * 2);
  for (std::size_t i = 0; i < FAKENECT_PIXELS; ++i) {
    if (raw[i] > 2047) {
      return err(bad(IoError::Code::BAD_NUMBER, name,
                     "pixel " + std::to_string(i) + " holds " + std::to_string(raw[i]) +
                         ", not an 11-bit disparity (a big-endian PGM, not a fakenect record?)"));
    }
  }
  return {};
}

Result<void, IoError> read_fakenect_depth(const std::filesystem::path& path,
                                          std::span<std::uint16_t> raw) {
  auto bytes = read_file_bytes(path, DEPTH_HEADER.size() + FAKENECT_PIXELS * 2 + 1);
  if (!bytes) return err(bytes.error());
  return parse_fakenect_depth(*bytes, path.string(), raw);
}

Result<void, IoError> write_fakenect_rgb(const std::filesystem::path& path,
                                         std::span<const std::uint8_t> rgb) {
  if (rgb.size() != FAKENECT_PIXELS * 3)
    return err(bad(IoError::Code::SIZE_MISMATCH, path.string(), "not 640x480 RGB"));
  return write_bytes(path, RGB_HEADER, rgb.data(), rgb.size());
}

Result<void, IoError> read_fakenect_rgb(const std::filesystem::path& path,
                                        std::span<std::uint8_t> rgb) {
  auto bytes = read_file_bytes(path, RGB_HEADER.size() + FAKENECT_PIXELS * 3 + 1);
  if (!bytes) return err(bytes.error());
  auto body = body_after(*bytes, RGB_HEADER, FAKENECT_PIXELS * 3, path.string());
  if (!body) return err(body.error());
  std::memcpy(rgb.data(), body->data(), FAKENECT_PIXELS * 3);
  return {};
}

Result<void, IoError> write_fakenect_tilt(const std::filesystem::path& path,
                                          const FakenectTilt& t) {
  std::array<char, 12> b{};
  auto put16 = [&](std::size_t at, std::int16_t v) {
    const auto u = static_cast<std::uint16_t>(v);
    b[at] = static_cast<char>(u & 0xFF);
    b[at + 1] = static_cast<char>(u >> 8);
  };
  put16(0, t.accel_x);
  put16(2, t.accel_y);
  put16(4, t.accel_z);
  b[6] = static_cast<char>(t.tilt_half_degrees);
  const auto status = static_cast<std::uint32_t>(t.status);
  for (std::size_t i = 0; i < 4; ++i) b[8 + i] = static_cast<char>((status >> (8 * i)) & 0xFF);
  return write_file_atomically(path, std::string_view(b.data(), b.size()));
}

Result<FakenectTilt, IoError> read_fakenect_tilt(const std::filesystem::path& path) {
  auto bytes = read_file_bytes(path, 13);
  if (!bytes) return err(bytes.error());
  if (bytes->size() != 12)
    return err(bad(IoError::Code::SIZE_MISMATCH, path.string(),
                   std::to_string(bytes->size()) + " bytes, a tilt record has 12"));
  const auto* p = reinterpret_cast<const std::uint8_t*>(bytes->data());
  auto get16 = [&](std::size_t at) {
    return static_cast<std::int16_t>(static_cast<std::uint16_t>(p[at] | (p[at + 1] << 8)));
  };
  FakenectTilt t;
  t.accel_x = get16(0);
  t.accel_y = get16(2);
  t.accel_z = get16(4);
  t.tilt_half_degrees = static_cast<std::int8_t>(p[6]);
  const auto byte = [&](std::size_t at, unsigned shift) {
    return static_cast<std::uint32_t>(p[at]) << shift;
  };
  t.status = static_cast<std::int32_t>(byte(8, 0) | byte(9, 8) | byte(10, 16) | byte(11, 24));
  return t;
}

}  // namespace orthoflow::formats
