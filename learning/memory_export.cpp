// Export and import of the perceptual memory as JSON lines (format in docs/LEARNING.md): line 1 is
// the header with the schema version and the representation parameters, then one line per view.
#include <algorithm>
#include <fstream>
#include <nlohmann/json.hpp>

#include "core/fnv.hpp"
#include "core/input_limit.hpp"
#include "learning/detail/memory_state.hpp"
#include "learning/detail/store_dir.hpp"
#include "learning/perceptual_memory.hpp"

namespace orthoflow::learning {
namespace {

using Code = MemoryError::Code;
using nlohmann::json;

json view_line(const std::string& label, const ViewRecord& v) {
  return json{{"label", label}, {"descriptor", v.descriptor}, {"frame", v.frame},
              {"bbox", v.bbox}, {"track_id", v.track_id},     {"stamp_ns", v.stamp_ns}};
}

// Copies exactly @p n finite numbers of array @p j into @p out.
bool read_floats(const json& j, std::size_t n, std::span<float> out) {
  if (!j.is_array() || j.size() != n || out.size() != n) { return false; }
  for (std::size_t i = 0; i < n; ++i) {
    if (!j[i].is_number()) { return false; }
    out[i] = j[i].get<float>();
  }
  return true;
}

// One view line; @p why says what is wrong when it returns false.
bool parse_view(const std::string& line, std::size_t length, std::string& label, ViewRecord& v,
                std::string& why) {
  const json j = json::parse(line, nullptr, false);
  if (j.is_discarded() || !j.is_object()) {
    why = "not a JSON object";
    return false;
  }
  const auto l = j.find("label");
  const auto d = j.find("descriptor");
  const auto f = j.find("frame");
  const auto b = j.find("bbox");
  const auto t = j.find("track_id");
  const auto s = j.find("stamp_ns");
  if (l == j.end() || !l->is_string() || d == j.end() || f == j.end() || b == j.end() ||
      t == j.end() || !t->is_number_unsigned() || s == j.end() || !s->is_number_integer()) {
    why = "needs \"label\", \"descriptor\", \"frame\", \"bbox\", \"track_id\" and \"stamp_ns\"";
    return false;
  }
  label = l->get<std::string>();
  v.descriptor.resize(length);
  if (!read_floats(*d, length, v.descriptor) || !read_floats(*f, 16, v.frame) ||
      !read_floats(*b, 3, v.bbox)) {
    why = "descriptor must hold " + std::to_string(length) + " numbers, frame 16, bbox 3";
    return false;
  }
  v.track_id = t->get<std::uint64_t>();
  v.stamp_ns = s->get<std::int64_t>();
  if (auto r = validate_label(label); !r) {
    why = to_string(r.error());
    return false;
  }
  if (auto r = validate_batch(DescriptorBatch{v.descriptor, length}, length, true); !r) {
    why = to_string(r.error());
    return false;
  }
  return true;
}

struct ImportGroup {
  std::string label;
  std::vector<ViewRecord> views;
};

constexpr std::size_t MAX_LINE_BYTES = 1 << 20;  // a view line is ~15 KB at 20 bins

// std::getline with bounds: a line longer than MAX_LINE_BYTES, or more than core::max_input_bytes()
// read in all, stops the read (an endless input such as /dev/zero never grows a string without
// end).
enum class LineRead { LINE, END, TOO_LONG };
LineRead read_line(std::istream& in, std::string& line, std::size_t& total) {
  line.clear();
  std::streambuf* buffer = in.rdbuf();
  for (int c = buffer->sbumpc(); c != std::char_traits<char>::eof(); c = buffer->sbumpc()) {
    if (++total > core::max_input_bytes() || line.size() == MAX_LINE_BYTES)
      return LineRead::TOO_LONG;
    if (c == '\n') return LineRead::LINE;
    line.push_back(static_cast<char>(c));
  }
  return line.empty() ? LineRead::END : LineRead::LINE;
}

// FNV-1a over @p text and a newline: the digest of an export file, line by line.
std::uint64_t fnv1a(std::string_view text, std::uint64_t h) {
  return core::fnv1a(core::fnv1a(h, text), static_cast<std::uint8_t>('\n'));
}

// The export header says how many views and categories follow; a file with fewer (cut short) or
// more lines is refused. Headers without the counts (hand-written files) are taken as they are.
Result<void, std::string> check_counts(const std::string& header_line, std::size_t views,
                                       std::size_t categories) {
  const json header = json::parse(header_line, nullptr, false);
  const auto v = header.find("views"), c = header.find("categories");
  if (v != header.end() && v->is_number_unsigned() && v->get<std::size_t>() != views) {
    return err("the header says " + std::to_string(v->get<std::size_t>()) +
               " views, the file has " + std::to_string(views) +
               " (truncated?): nothing was imported");
  }
  if (c != header.end() && c->is_number_unsigned() && c->get<std::size_t>() != categories) {
    return err("the header says " + std::to_string(c->get<std::size_t>()) +
               " categories, the file has " + std::to_string(categories) +
               ": nothing was imported");
  }
  return {};
}

std::string import_key(std::uint64_t digest) {
  static constexpr char HEX[] = "0123456789abcdef";
  std::string key = "i";
  for (int shift = 60; shift >= 0; shift -= 4) key += HEX[(digest >> shift) & 0xFU];
  return key;
}

// One synced batch for every category of the file plus the import marker; the index and the learner
// take the categories only after it.
Result<std::size_t, MemoryError> commit_import(PerceptualMemory::State& s,
                                               const std::filesystem::path& file,
                                               const std::vector<ImportGroup>& groups,
                                               std::uint64_t digest, std::size_t count) {
  std::string seen;
  if (s.db->Get(leveldb::ReadOptions(), import_key(digest), &seen).ok()) {
    return err(
        memory_error(Code::BAD_IMPORT, file,
                     "this export was imported into the store already: nothing was imported"));
  }
  leveldb::WriteBatch batch;
  CategoryId next_id = s.next_id;
  std::vector<StagedTeach> staged;
  for (const ImportGroup& g : groups) {
    auto one = stage_teach(s, g.label, g.views, next_id, batch, ViewSource::IMPORT);
    if (!one) return err(one.error());
    staged.push_back(std::move(*one));
  }
  batch.Put(std::string(KEY_NEXT_ID), encode_u32(next_id));
  batch.Put(import_key(digest), std::to_string(count));
  if (auto r = write_synced(s, batch, "import " + file.string()); !r) return err(r.error());
  for (const StagedTeach& t : staged) apply_staged(s, t);
  return count;
}

}  // namespace

Result<std::size_t, MemoryError> PerceptualMemory::export_to(
    const std::filesystem::path& file) const {
  const State& s = *state_;
  if (inside_store(file, s.dir)) {
    return err(
        memory_error(Code::FILE_FAILED, file, "is inside the store it would export: refused"));
  }
  std::ofstream out(file, std::ios::binary | std::ios::trunc);
  if (!out) { return err(memory_error(Code::FILE_FAILED, file, "cannot open for writing")); }
  json header = json::parse(encode_schema(s.cfg.descriptor));
  header["format"] = "orthoflow-memory";
  header["categories"] = s.index.size();
  header["views"] = stats().views;
  out << header.dump() << '\n';
  std::size_t written = 0;
  for (const IndexedCategory& c : s.index) {
    auto views_result = State::read_views(*state_, c.id);
    if (!views_result) { return err(views_result.error()); }
    for (const ViewRecord& v : *views_result) {
      out << view_line(c.record.label, v).dump() << '\n';
      ++written;
    }
  }
  out.flush();
  if (!out) { return err(memory_error(Code::FILE_FAILED, file, "write failed")); }
  return written;
}

Result<std::size_t, MemoryError> PerceptualMemory::import_from(const std::filesystem::path& file) {
  std::ifstream in(file, std::ios::binary);
  if (!in) { return err(memory_error(Code::FILE_FAILED, file, "cannot open for reading")); }
  std::string line;
  std::uint32_t version = 0;
  std::string why;
  std::size_t total = 0;
  const LineRead first = read_line(in, line, total);
  if (first == LineRead::TOO_LONG)
    return err(memory_error(Code::BAD_IMPORT, file, "line 1 is too long"));
  const auto params = first == LineRead::LINE ? decode_schema(line, version, why) : std::nullopt;
  const std::string header_line = line;
  if (!params || version != MEMORY_SCHEMA_VERSION || !(*params == state_->cfg.descriptor)) {
    const std::string reason =
        !params ? (why.empty() ? "empty file" : why)
        : version != MEMORY_SCHEMA_VERSION
            ? "schema version " + std::to_string(version)
            : "file has " + params->describe() + ", store has " + state_->cfg.descriptor.describe();
    return err(memory_error(Code::BAD_IMPORT, file, "line 1: " + reason));
  }
  // Everything is parsed and checked first, then written in ONE synced batch with a marker of this
  // file's content: a bad line, a short file or a kill imports nothing, and the same export twice
  // is refused the second time.
  std::vector<ImportGroup> groups;
  std::size_t count = 0;
  std::uint64_t digest = fnv1a(line, core::FNV_OFFSET);
  LineRead got = LineRead::LINE;
  for (std::size_t number = 2; (got = read_line(in, line, total)) == LineRead::LINE; ++number) {
    digest = fnv1a(line, digest);
    if (line.empty()) { continue; }
    std::string label;
    ViewRecord v;
    if (!parse_view(line, state_->learner->descriptor_length(), label, v, why)) {
      return err(
          memory_error(Code::BAD_IMPORT, file, "line " + std::to_string(number) + ": " + why));
    }
    auto g = std::find_if(groups.begin(), groups.end(),
                          [&](const ImportGroup& e) { return e.label == label; });
    if (g == groups.end()) { g = groups.insert(groups.end(), ImportGroup{label, {}}); }
    g->views.push_back(std::move(v));
    ++count;
  }
  if (got == LineRead::TOO_LONG) {
    return err(memory_error(Code::BAD_IMPORT, file,
                            "a line longer than " + std::to_string(MAX_LINE_BYTES) +
                                " bytes, or more than the input limit of " +
                                std::to_string(core::max_input_bytes()) +
                                " bytes: nothing was imported"));
  }
  if (auto r = check_counts(header_line, count, groups.size()); !r) {
    return err(memory_error(Code::BAD_IMPORT, file, r.error()));
  }
  return commit_import(*state_, file, groups, digest, count);
}

}  // namespace orthoflow::learning
