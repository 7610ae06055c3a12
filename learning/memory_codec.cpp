// The perceptual memory's LevelDB keys and binary records (learning/detail/memory_codec.hpp,
// docs/LEARNING.md): categories, Bayes models, views and counters. The schema JSON is in
// memory_schema.cpp.
#include "learning/detail/memory_codec.hpp"

#include <bit>
#include <cmath>
#include <cstring>
#include <sstream>

namespace orthoflow::learning {
namespace {

// Values are written with memcpy of native numbers; the format is little-endian (docs/LEARNING.md).
static_assert(std::endian::native == std::endian::little, "the memory format is little-endian");

constexpr std::uint32_t VIEW_MAGIC = 0x3156464FU;  // "OFV1"
// Largest descriptor a record may declare (GOOD_MAX_BINS): a corrupt length never triggers a huge
// allocation.
constexpr std::size_t MAX_VALUES = 3 * kernels::GOOD_MAX_BINS * kernels::GOOD_MAX_BINS;

class Writer {
 public:
  template <class T>
  Writer& put(const T& v) {
    const auto* p = reinterpret_cast<const char*>(&v);
    out_.append(p, sizeof(T));
    return *this;
  }
  template <class T>
  Writer& put_all(std::span<const T> values) {
    out_.append(reinterpret_cast<const char*>(values.data()), values.size_bytes());
    return *this;
  }
  std::string take() { return std::move(out_); }

 private:
  std::string out_;
};

class Reader {
 public:
  explicit Reader(std::string_view bytes) : bytes_(bytes) {}
  template <class T>
  bool get(T& v) noexcept {
    if (bytes_.size() < sizeof(T)) { return false; }
    std::memcpy(&v, bytes_.data(), sizeof(T));
    bytes_.remove_prefix(sizeof(T));
    return true;
  }
  template <class T>
  bool get_all(std::span<T> values) noexcept {
    if (bytes_.size() < values.size_bytes()) { return false; }
    std::memcpy(values.data(), bytes_.data(), values.size_bytes());
    bytes_.remove_prefix(values.size_bytes());
    return true;
  }
  [[nodiscard]] std::size_t left() const noexcept { return bytes_.size(); }
  [[nodiscard]] std::string_view rest() const noexcept { return bytes_; }

 private:
  std::string_view bytes_;
};

void put_be(std::string& key, std::uint64_t v, int bytes) {
  for (int b = bytes - 1; b >= 0; --b) { key.push_back(static_cast<char>((v >> (8 * b)) & 0xFFU)); }
}

}  // namespace

std::string category_key(char kind, CategoryId id) {
  std::string key(1, kind);
  put_be(key, id, 4);
  return key;
}

std::string view_key(CategoryId id, std::uint64_t seq) {
  std::string key = category_key(KIND_VIEW, id);
  put_be(key, seq, 8);
  return key;
}

std::optional<CategoryId> key_category(std::string_view key) noexcept {
  if (key.size() < 5) { return std::nullopt; }
  CategoryId id = 0;
  for (std::size_t i = 1; i < 5; ++i) { id = (id << 8U) | static_cast<unsigned char>(key[i]); }
  return id;
}

std::string encode_category(const CategoryRecord& c) {
  Writer w;
  w.put(c.next_seq).put(c.views);
  std::string out = w.take();
  return out + c.label;
}

std::optional<CategoryRecord> decode_category(std::string_view bytes) {
  Reader r(bytes);
  CategoryRecord c;
  if (!r.get(c.next_seq) || !r.get(c.views) || r.left() == 0 || r.left() > LABEL_MAX_BYTES) {
    return std::nullopt;
  }
  c.label = std::string(r.rest());
  return c;
}

std::string encode_model(const ModelRecord& m) {
  Writer w;
  w.put(m.seen)
      .put(static_cast<std::uint32_t>(m.sums.size()))
      .put_all(std::span<const double>(m.sums));
  return w.take();
}

std::optional<ModelRecord> decode_model(std::string_view bytes) {
  Reader r(bytes);
  ModelRecord m;
  std::uint32_t n = 0;
  if (!r.get(m.seen) || !r.get(n) || n > MAX_VALUES || r.left() != n * sizeof(double)) {
    return std::nullopt;
  }
  m.sums.resize(n);
  if (!r.get_all(std::span<double>(m.sums))) { return std::nullopt; }
  return m;
}

std::string encode_view(const ViewRecord& v, const kernels::DescriptorSpec& spec) {
  Writer w;
  w.put(VIEW_MAGIC)
      .put(static_cast<std::uint32_t>(spec.good.bins))
      .put(static_cast<std::uint8_t>(spec.good.mode));
  w.put(spec.good.effective_threshold());
  w.put_all(std::span<const float>(v.frame)).put_all(std::span<const float>(v.bbox));
  w.put(v.track_id).put(v.stamp_ns).put(static_cast<std::uint32_t>(v.descriptor.size()));
  w.put_all(std::span<const float>(v.descriptor));
  return w.take();
}

std::optional<ViewRecord> decode_view(std::string_view bytes,
                                      const kernels::DescriptorSpec& expected, std::string& why) {
  Reader r(bytes);
  std::uint32_t magic = 0, bins = 0, n = 0;
  std::uint8_t mode = 0;
  float threshold = 0.0F;
  ViewRecord v;
  if (!r.get(magic) || magic != VIEW_MAGIC) {
    why = "view record does not start with OFV1";
    return std::nullopt;
  }
  if (!r.get(bins) || !r.get(mode) || !r.get(threshold) || !r.get_all(std::span<float>(v.frame)) ||
      !r.get_all(std::span<float>(v.bbox)) || !r.get(v.track_id) || !r.get(v.stamp_ns) ||
      !r.get(n)) {
    why = "view record truncated in its header";
    return std::nullopt;
  }
  // The record names its GOOD parameters (a bag-of-words store's frame and box); the rest of the
  // specification (the dictionary) is the store's, checked when it was opened.
  kernels::DescriptorSpec got = expected;
  got.good.bins = bins;
  got.good.mode = mode == 0 ? kernels::GoodMode::INVARIANT : kernels::GoodMode::REFERENCE;
  got.good.threshold = threshold;
  if (mode > 1 || !(got == expected) || n != expected.length() || r.left() != n * sizeof(float)) {
    why = "view record has " + got.describe() + " and " + std::to_string(n) +
          " values, store has " + expected.describe();
    return std::nullopt;
  }
  v.descriptor.resize(n);
  (void)r.get_all(std::span<float>(v.descriptor));
  return v;
}

std::string encode_u32(std::uint32_t v) {
  Writer w;
  w.put(v);
  return w.take();
}

std::optional<std::uint32_t> decode_u32(std::string_view bytes) noexcept {
  Reader r(bytes);
  std::uint32_t v = 0;
  if (!r.get(v) || r.left() != 0) { return std::nullopt; }
  return v;
}

}  // namespace orthoflow::learning
