#include "formats/tum_rgbd.hpp"

#include <array>
#include <cmath>

#include "formats/file_bytes.hpp"
#include "formats/text_scan.hpp"

namespace orthoflow::formats {

namespace {

constexpr double MAX_SECONDS = 1.0e10;  // year 2286: a larger "timestamp" is not a time

bool is_timestamp(std::string_view token, double& seconds) {
  return parse_number(token, seconds) && std::isfinite(seconds) && seconds >= 0.0 &&
         seconds < MAX_SECONDS;
}

/// A relative path to a PNG inside the folder: no root, no "..", no control characters.
bool is_inside_png(std::string_view file) {
  if (file.empty() || file.front() == '/' || file.size() < 5 ||
      file.substr(file.size() - 4) != ".png")
    return false;
  for (const char c : file) {
    if (static_cast<unsigned char>(c) < 0x20 || c == 0x7F || c == '\\') return false;
  }
  std::size_t at = 0;
  while (at <= file.size()) {
    const std::size_t end = std::min(file.find('/', at), file.size());
    const std::string_view part = file.substr(at, end - at);
    if (part.empty() || part == "..") return false;
    at = end + 1;
  }
  return true;
}

bool under_depth(std::string_view file) { return file.substr(0, 6) == "depth/"; }

}  // namespace

Result<TumDepthList, IoError> parse_tum_depth_list(std::string_view text, const std::string& name,
                                                   bool associated) {
  TumDepthList list;
  list.listing = associated ? "associate.txt" : "depth.txt";
  LineCursor lines(std::span<const char>(text.data(), text.size()));
  std::string_view line;
  while (lines.next(line)) {
    const auto where = [&] {
      return name + ": line " + std::to_string(lines.line_number()) + ": ";
    };
    std::array<std::string_view, 4> tokens;
    bool more = false;
    const std::size_t n = split_ws(line, tokens, more);
    if (n == 0 || tokens[0].front() == '#') continue;
    std::string_view stamp, file;
    if (!associated) {
      if (n != 2 || more)
        return err(IoError{IoError::Code::BAD_HEADER, where() + "expected '<timestamp> <file>'"});
      stamp = tokens[0];
      file = tokens[1];
    } else {
      if (n < 4)
        return err(IoError{IoError::Code::BAD_HEADER,
                           where() + "expected '<timestamp> <file> <timestamp> <file>'"});
      if (under_depth(tokens[1]) == under_depth(tokens[3]))
        return err(IoError{IoError::Code::BAD_HEADER,
                           where() + "exactly one of the two files must be under depth/"});
      const std::size_t k = under_depth(tokens[1]) ? 0 : 2;
      stamp = tokens[k];
      file = tokens[k + 1];
    }
    double seconds = 0.0;
    if (!is_timestamp(stamp, seconds))
      return err(IoError{IoError::Code::BAD_NUMBER,
                         where() + "'" + std::string(stamp) + "' is not a timestamp in seconds"});
    if (!is_inside_png(file))
      return err(IoError{
          IoError::Code::BAD_HEADER,
          where() + "'" + std::string(file) + "' is not a relative .png path inside the folder"});
    if (!list.entries.empty() && seconds <= list.entries.back().seconds) {
      ++list.out_of_order;
      continue;
    }
    list.entries.push_back(TumDepthEntry{seconds, std::string(file)});
  }
  return list;
}

Result<TumDepthList, IoError> read_tum_depth_list(const std::filesystem::path& dir) {
  const bool associated = std::filesystem::exists(dir / "associate.txt");
  const auto path = dir / (associated ? "associate.txt" : "depth.txt");
  auto bytes = read_file_bytes(path, std::size_t{64} << 20);
  if (!bytes) return err(bytes.error());
  auto list = parse_tum_depth_list(std::string_view(bytes->data(), bytes->size()), path.string(),
                                   associated);
  if (list && list->entries.empty())
    return err(IoError{IoError::Code::BAD_HEADER, path.string() + ": lists no depth image"});
  return list;
}

}  // namespace orthoflow::formats
