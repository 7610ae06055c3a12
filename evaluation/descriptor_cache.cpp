// The cache format: "OFDC" u32 version=1, u64 length, u64 count, then per entry u32 path bytes,
// path, u64 size, i64 mtime_ns, length floats. Host byte order: the cache is a local file, never
// exchanged.
#include "evaluation/descriptor_cache.hpp"

#include <unistd.h>
#include <algorithm>
#include <chrono>
#include <cstring>
#include <fstream>
#include <system_error>

namespace orthoflow::evaluation {
namespace {

constexpr char MAGIC[4] = {'O', 'F', 'D', 'C'};
constexpr std::uint32_t VERSION = 1;
constexpr std::size_t MAX_PATH_BYTES = 4096;

/// Reads fixed-size values from a byte span, failing (not reading) past its end.
struct Reader {
  std::span<const char> bytes;
  std::size_t at = 0;
  template <class T>
  bool get(T& out) {
    if (bytes.size() - at < sizeof(T)) { return false; }
    std::memcpy(&out, bytes.data() + at, sizeof(T));
    at += sizeof(T);
    return true;
  }
  bool get_bytes(void* out, std::size_t n) {
    if (bytes.size() - at < n) { return false; }
    std::memcpy(out, bytes.data() + at, n);
    at += n;
    return true;
  }
};

template <class T>
void put(std::string& out, const T& v) {
  out.append(reinterpret_cast<const char*>(&v), sizeof(T));
}

bool parse_entry(Reader& r, DescriptorCache& cache) {
  std::uint32_t path_bytes = 0;
  if (!r.get(path_bytes) || path_bytes == 0 || path_bytes > MAX_PATH_BYTES) { return false; }
  std::string path(path_bytes, '\0');
  DescriptorCache::Entry e;
  e.descriptor.resize(cache.length);
  return r.get_bytes(path.data(), path_bytes) && r.get(e.stamp.size) && r.get(e.stamp.mtime_ns) &&
         r.get_bytes(e.descriptor.data(), cache.length * sizeof(float)) &&
         cache.entries.emplace(std::move(path), std::move(e)).second;
}

}  // namespace

bool stamp_file(const std::filesystem::path& path, FileStamp& out) {
  std::error_code ec;
  const auto size = std::filesystem::file_size(path, ec);
  if (ec) { return false; }
  const auto mtime = std::filesystem::last_write_time(path, ec);
  if (ec) { return false; }
  out.size = size;
  out.mtime_ns =
      std::chrono::duration_cast<std::chrono::nanoseconds>(mtime.time_since_epoch()).count();
  return true;
}

DescriptorCache parse_descriptor_cache(std::span<const char> bytes, std::size_t length) {
  DescriptorCache cache;
  cache.length = length;
  Reader r{bytes};
  char magic[4] = {};
  std::uint32_t version = 0;
  std::uint64_t stored_length = 0, count = 0;
  if (!r.get_bytes(magic, 4) || std::memcmp(magic, MAGIC, 4) != 0 || !r.get(version) ||
      version != VERSION || !r.get(stored_length) || stored_length != length || length == 0 ||
      !r.get(count)) {
    return cache;
  }
  // Each entry takes at least 21 + 4 length bytes: a count beyond that cannot be honest.
  if (count > bytes.size() / (21 + 4 * length)) { return cache; }
  for (std::uint64_t i = 0; i < count; ++i) {
    if (!parse_entry(r, cache)) { return DescriptorCache{length, {}}; }
  }
  if (r.at != bytes.size()) { return DescriptorCache{length, {}}; }
  return cache;
}

std::string encode_descriptor_cache(const DescriptorCache& cache) {
  std::string out(MAGIC, 4);
  put(out, VERSION);
  put(out, static_cast<std::uint64_t>(cache.length));
  put(out, static_cast<std::uint64_t>(cache.entries.size()));
  // Sorted by path so the same cache gives the same bytes.
  std::vector<const std::pair<const std::string, DescriptorCache::Entry>*> sorted;
  for (const auto& kv : cache.entries) { sorted.push_back(&kv); }
  std::sort(sorted.begin(), sorted.end(),
            [](const auto* a, const auto* b) { return a->first < b->first; });
  for (const auto* kv : sorted) {
    put(out, static_cast<std::uint32_t>(kv->first.size()));
    out += kv->first;
    put(out, kv->second.stamp.size);
    put(out, kv->second.stamp.mtime_ns);
    out.append(reinterpret_cast<const char*>(kv->second.descriptor.data()),
               kv->second.descriptor.size() * sizeof(float));
  }
  return out;
}

std::string save_descriptor_cache(const DescriptorCache& cache, const std::filesystem::path& path) {
  std::error_code ec;
  std::filesystem::create_directories(path.parent_path(), ec);
  if (ec) { return "cannot create " + path.parent_path().string() + ": " + ec.message(); }
  const std::filesystem::path tmp = path.string() + ".tmp" + std::to_string(::getpid());
  {
    std::ofstream f(tmp, std::ios::binary | std::ios::trunc);
    const std::string bytes = encode_descriptor_cache(cache);
    f.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
    if (!f.flush()) { return "cannot write " + tmp.string(); }
  }
  std::filesystem::rename(tmp, path, ec);
  if (ec) {
    std::filesystem::remove(tmp, ec);
    return "cannot rename the cache into " + path.string();
  }
  return {};
}

}  // namespace orthoflow::evaluation
