// The dictionary's file (learning/dictionary.hpp): encode, parse (fuzzed), save durably, load.
#include "learning/dictionary.hpp"

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstring>
#include <fstream>
#include <sstream>

#include "core/file_output.hpp"

namespace orthoflow::learning {

namespace {

static_assert(std::endian::native == std::endian::little, "the dictionary format is little-endian");

constexpr char MAGIC[4] = {'O', 'F', 'W', 'D'};
constexpr std::uint32_t VERSION = 1;         ///< words only
constexpr std::uint32_t VERSION_TOPICS = 2;  ///< words, then a topic model of them
constexpr std::uint64_t MAX_TOPICS = 1024;
constexpr std::uint64_t MAX_WORDS = 1U << 16;
constexpr std::uint64_t MAX_PROVENANCE = 1U << 16;

template <class T>
void put(std::string& out, const T& v) {
  out.append(reinterpret_cast<const char*>(&v), sizeof(T));
}

template <class T>
bool get(std::span<const char>& in, T& v) noexcept {
  if (in.size() < sizeof(T)) return false;
  std::memcpy(&v, in.data(), sizeof(T));
  in = in.subspan(sizeof(T));
  return true;
}

}  // namespace

std::string encode_dictionary(const kernels::VisualDictionary& d) {
  std::string out(MAGIC, sizeof MAGIC);
  put(out, d.topics ? VERSION_TOPICS : VERSION);
  put(out, static_cast<std::uint64_t>(d.words));
  put(out, static_cast<std::uint64_t>(d.dims));
  put(out, d.spin.image_width);
  put(out, d.spin.support_length);
  put(out, d.spin.support_angle_cos);
  put(out, d.keypoint_leaf);
  put(out, d.normal_radius);
  put(out, d.id);
  put(out, static_cast<std::uint64_t>(d.provenance.size()));
  out += d.provenance;
  out.append(reinterpret_cast<const char*>(d.data.data()), d.data.size() * sizeof(float));
  if (d.topics) {  // version 2: K, alpha, beta, iterations, seed, then n_kw (K x V)
    const kernels::TopicModel& t = *d.topics;
    put(out, static_cast<std::uint64_t>(t.topics));
    put(out, t.alpha);
    put(out, t.beta);
    put(out, t.iterations);
    put(out, t.seed);
    out.append(reinterpret_cast<const char*>(t.word_topic.data()),
               t.word_topic.size() * sizeof(std::uint32_t));
  }
  return out;
}

Result<kernels::VisualDictionary, std::string> parse_dictionary(std::span<const char> bytes) {
  if (bytes.size() < sizeof MAGIC || std::memcmp(bytes.data(), MAGIC, sizeof MAGIC) != 0)
    return err(std::string("not a dictionary file (no OFWD magic)"));
  bytes = bytes.subspan(sizeof MAGIC);
  std::uint32_t version = 0;
  std::uint64_t words = 0, dims = 0, provenance = 0;
  kernels::VisualDictionary d;
  if (!get(bytes, version)) return err(std::string("dictionary file truncated in its header"));
  if (version != VERSION && version != VERSION_TOPICS)
    return err("dictionary file version " + std::to_string(version) + ", this build reads " +
               std::to_string(VERSION) + " and " + std::to_string(VERSION_TOPICS));
  if (!get(bytes, words) || !get(bytes, dims) || !get(bytes, d.spin.image_width) ||
      !get(bytes, d.spin.support_length) || !get(bytes, d.spin.support_angle_cos) ||
      !get(bytes, d.keypoint_leaf) || !get(bytes, d.normal_radius) || !get(bytes, d.id) ||
      !get(bytes, provenance))
    return err(std::string("dictionary file truncated in its header"));
  if (d.spin.image_width == 0 || d.spin.image_width > kernels::MAX_SPIN_IMAGE_WIDTH ||
      dims != kernels::spin_image_bins(d.spin.image_width) || words == 0 || words > MAX_WORDS ||
      provenance > MAX_PROVENANCE)
    return err("dictionary file header is inconsistent (" + std::to_string(words) + " words of " +
               std::to_string(dims) + " values, image width " + std::to_string(d.spin.image_width) +
               ")");
  const std::uint64_t body = provenance + words * dims * sizeof(float);
  if (version == VERSION ? bytes.size() != body : bytes.size() < body)
    return err("dictionary file holds " + std::to_string(bytes.size()) +
               " bytes after its header, " + std::to_string(body) +
               (version == VERSION ? " expected" : " and a topic model expected"));
  d.words = words;
  d.dims = dims;
  d.provenance.assign(bytes.data(), provenance);
  bytes = bytes.subspan(provenance);
  d.data.resize(words * dims);
  std::memcpy(d.data.data(), bytes.data(), d.data.size() * sizeof(float));
  if (!std::all_of(d.data.begin(), d.data.end(), [](float v) { return std::isfinite(v); }))
    return err(std::string("dictionary file has a word value that is not finite"));
  bytes = bytes.subspan(d.data.size() * sizeof(float));
  if (version == VERSION_TOPICS) {
    kernels::TopicModel t;
    std::uint64_t topics = 0;
    if (!get(bytes, topics) || !get(bytes, t.alpha) || !get(bytes, t.beta) ||
        !get(bytes, t.iterations) || !get(bytes, t.seed))
      return err(std::string("dictionary file truncated in its topic model's header"));
    if (topics == 0 || topics > MAX_TOPICS || !(t.alpha > 0.0) || !(t.beta > 0.0) ||
        !std::isfinite(t.alpha) || !std::isfinite(t.beta) || t.iterations > 100000)
      return err("dictionary file's topic model is inconsistent (" + std::to_string(topics) +
                 " topics)");
    if (bytes.size() != topics * words * sizeof(std::uint32_t))
      return err("dictionary file holds " + std::to_string(bytes.size()) +
                 " bytes of topic counts, " +
                 std::to_string(topics * words * sizeof(std::uint32_t)) + " expected");
    t.topics = topics;
    t.words = words;
    t.word_topic.resize(topics * words);
    std::memcpy(t.word_topic.data(), bytes.data(), bytes.size());
    t.topic_total.assign(topics, 0);
    for (std::size_t k = 0; k < topics; ++k) {
      std::uint64_t sum = 0;
      for (std::size_t w = 0; w < words; ++w) sum += t.word_topic[k * words + w];
      if (sum > UINT32_MAX) return err(std::string("dictionary file's topic counts overflow"));
      t.topic_total[k] = static_cast<std::uint32_t>(sum);
    }
    d.topics = std::move(t);
  }
  const std::uint64_t id = kernels::dictionary_id(d);
  if (id != d.id)
    return err("dictionary file is corrupt: its words hash to " + kernels::dictionary_id_hex(id) +
               ", its header says " + kernels::dictionary_id_hex(d.id));
  return d;
}

std::string save_dictionary(const kernels::VisualDictionary& d, const std::filesystem::path& path) {
  auto written = core::write_whole_file(path, encode_dictionary(d), /*synced=*/true);
  return written ? std::string() : std::move(written.error());
}

Result<kernels::VisualDictionary, std::string> load_dictionary(const std::filesystem::path& path) {
  std::ifstream f(path, std::ios::binary);
  if (!f) return err("cannot open the dictionary " + path.string());
  std::ostringstream s;
  s << f.rdbuf();
  const std::string bytes = s.str();
  auto d = parse_dictionary(bytes);
  if (!d) return err(path.string() + ": " + d.error());
  return d;
}

}  // namespace orthoflow::learning
