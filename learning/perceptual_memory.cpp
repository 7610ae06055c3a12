// Opening a perceptual memory (learning/perceptual_memory.hpp): the store directory checked, the
// schema compared, every category loaded into the learner; and the memory's read-only queries. Its
// errors are in memory_error.cpp, its writes in memory_write.cpp.
#include "learning/perceptual_memory.hpp"

#include <leveldb/write_batch.h>

#include <algorithm>

#include "learning/detail/log_tail.hpp"
#include "learning/detail/memory_state.hpp"
#include "learning/detail/store_dir.hpp"
#include "learning/dictionary.hpp"

namespace orthoflow::learning {
namespace {

using Code = MemoryError::Code;

std::unique_ptr<Learner> learner_for(MemoryConfig& cfg) {
  const std::size_t length = cfg.descriptor.length();
  cfg.instance.descriptor_length = length;
  cfg.bayes.descriptor_length = length;
  return learning::make_learner(cfg.descriptor, cfg.learner, cfg.instance, cfg.bayes);
}

// The schema key: written when the store was just created, compared on every later open. A LevelDB
// database without it is not ours and is left alone.
Result<void, MemoryError> check_schema(PerceptualMemory::State& s, bool created) {
  std::string value;
  const leveldb::Status st = s.db->Get(leveldb::ReadOptions(), std::string(KEY_SCHEMA), &value);
  if (st.IsNotFound() && !created) {
    return err(
        memory_error(Code::OPEN_FAILED, s.dir,
                     "a LevelDB database without orthoflow's schema key: not a perceptual memory; "
                     "nothing was changed"));
  }
  const bool bow = s.cfg.descriptor.local();  // bag of words or topics: over a dictionary
  if (st.IsNotFound()) {
    if (auto valid = s.cfg.descriptor.validate(); !valid) {
      return err(
          memory_error(Code::PARAMS_MISMATCH, s.dir,
                       "a new store needs a whole descriptor specification: " + valid.error()));
    }
    leveldb::WriteOptions sync;
    sync.sync = true;
    leveldb::WriteBatch batch;
    batch.Put(std::string(KEY_SCHEMA), encode_schema(s.cfg.descriptor));
    if (bow)
      batch.Put(std::string(KEY_DICTIONARY), encode_dictionary(*s.cfg.descriptor.dictionary));
    batch.Put(std::string(KEY_NEXT_ID), encode_u32(0));
    if (!s.db->Write(sync, &batch).ok()) {
      return err(memory_error(Code::WRITE_FAILED, s.dir, "cannot write the schema key"));
    }
    return {};
  }
  if (!st.ok()) { return err(memory_error(Code::CORRUPT, s.dir, "schema key: " + st.ToString())); }
  std::uint32_t version = 0;
  std::string why;
  auto stored = decode_schema(value, version, why);
  if (!stored || version != MEMORY_SCHEMA_VERSION) {
    return err(
        memory_error(Code::CORRUPT, s.dir,
                     "schema key: " + (stored ? "version " + std::to_string(version) : why)));
  }
  if (stored->local()) {
    // The store's own dictionary: its words are in the "d" record, which must be the one the
    // schema names.
    std::string bytes;
    if (!s.db->Get(leveldb::ReadOptions(), std::string(KEY_DICTIONARY), &bytes).ok()) {
      return err(memory_error(Code::CORRUPT, s.dir, "a bag-of-words store without its dictionary"));
    }
    auto own = parse_dictionary(bytes);
    if (!own || own->id != stored->dictionary->id) {
      return err(memory_error(
          Code::CORRUPT, s.dir,
          "the stored dictionary " + (own ? kernels::dictionary_id_hex(own->id) + " is not the one "
                                                                                  "its schema names"
                                          : own.error())));
    }
    stored->dictionary = std::make_shared<const kernels::VisualDictionary>(std::move(own.value()));
    if (bow && !s.cfg.descriptor.dictionary &&
        stored->kind == s.cfg.descriptor.kind) {  // opened as "bow" without words: the store's own
      s.cfg.descriptor = *stored;
      s.learner = learner_for(s.cfg);
    }
  }
  if (!(*stored == s.cfg.descriptor)) {
    return err(memory_error(Code::PARAMS_MISMATCH, s.dir,
                            "store was created with " + stored->describe() + ", opened with " +
                                s.cfg.descriptor.describe()));
  }
  return {};
}

// Reads every "c", "m" and "v" record in key order and hands the categories to the learner.
Result<void, MemoryError> load(PerceptualMemory::State& s) {
  std::string next;
  if (!s.db->Get(leveldb::ReadOptions(), std::string(KEY_NEXT_ID), &next).ok() ||
      !decode_u32(next)) {
    return err(memory_error(Code::CORRUPT, s.dir, "next-id key missing or malformed"));
  }
  s.next_id = *decode_u32(next);
  std::vector<std::vector<float>> values;
  std::unique_ptr<leveldb::Iterator> it(s.db->NewIterator(leveldb::ReadOptions()));
  for (it->Seek(std::string(1, KIND_CATEGORY));
       it->Valid() && it->key().size() > 0 && it->key()[0] == KIND_CATEGORY; it->Next()) {
    const auto id = key_category(as_view(it->key()));
    auto rec = decode_category(as_view(it->value()));
    std::string model_bytes;
    const bool has_model =
        s.db->Get(leveldb::ReadOptions(), category_key(KIND_MODEL, id.value_or(0)), &model_bytes)
            .ok();
    auto model = has_model ? decode_model(model_bytes) : std::nullopt;
    if (!id || !rec || !model) {
      return err(memory_error(Code::CORRUPT, s.dir, "category record or model malformed"));
    }
    s.index.push_back(IndexedCategory{*id, std::move(*rec), std::move(*model)});
  }
  for (IndexedCategory& c : s.index) {
    auto views_result = PerceptualMemory::State::read_views(s, c.id);
    if (!views_result) { return err(views_result.error()); }
    std::vector<float>& flat = values.emplace_back();
    for (const ViewRecord& v : *views_result) {
      flat.insert(flat.end(), v.descriptor.begin(), v.descriptor.end());
    }
    if (views_result->size() != c.record.views ||
        c.model.sums.size() != s.learner->descriptor_length()) {
      return err(memory_error(Code::CORRUPT, s.dir,
                              "category " + std::to_string(c.id) + " (" + c.record.label +
                                  "): view count or model length disagrees with its record"));
    }
  }
  std::vector<RestoredCategory> restored;
  for (std::size_t k = 0; k < s.index.size(); ++k) {
    const IndexedCategory& c = s.index[k];
    restored.push_back(RestoredCategory{c.id, c.record.label,
                                        DescriptorBatch{values[k], s.learner->descriptor_length()},
                                        c.model.sums, c.model.seen});
  }
  if (auto r = s.learner->restore(restored, s.next_id); !r) {
    return err(memory_error(Code::CORRUPT, s.dir,
                            std::string("stored categories refused: ") + to_string(r.error())));
  }
  return {};
}

}  // namespace

Result<std::vector<ViewRecord>, MemoryError> PerceptualMemory::State::read_views(State& s,
                                                                                 CategoryId id) {
  std::vector<ViewRecord> out;
  const std::string prefix = category_key(KIND_VIEW, id);
  std::unique_ptr<leveldb::Iterator> it(s.db->NewIterator(leveldb::ReadOptions()));
  for (it->Seek(prefix); it->Valid() && it->key().starts_with(prefix); it->Next()) {
    std::string why;
    auto view = decode_view(as_view(it->value()), s.cfg.descriptor, why);
    if (!view) {
      return err(memory_error(
          Code::CORRUPT, s.dir,
          "category " + std::to_string(id) + " view " + std::to_string(out.size()) + ": " + why));
    }
    out.push_back(std::move(*view));
  }
  if (!it->status().ok()) {
    return err(memory_error(Code::CORRUPT, s.dir, it->status().ToString()));
  }
  return out;
}

PerceptualMemory::State::~State() {
  db.reset();  // close LevelDB before its private copy goes
  std::error_code ignored;
  if (!copy.empty()) std::filesystem::remove_all(copy, ignored);
}

namespace {

// Where LevelDB is pointed, and whether it may create: refuses everything that is not a store (or,
// in CREATE mode, an absent or empty directory), before LevelDB can touch it.
Result<bool, MemoryError> prepare(PerceptualMemory::State& s, OpenMode mode) {
  switch (inspect_store_dir(s.dir)) {
    case StoreDir::ABSENT:
    case StoreDir::EMPTY:
      if (mode != OpenMode::CREATE) {
        return err(memory_error(Code::OPEN_FAILED, s.dir,
                                "no perceptual memory here (nothing was created)"));
      }
      return true;
    case StoreDir::DAMAGED:
      return err(memory_error(
          Code::CORRUPT, s.dir,
          "LevelDB files without CURRENT: a damaged store; nothing was changed (restore "
          "CURRENT from a backup, or repair a copy)"));
    case StoreDir::FOREIGN:
      return err(memory_error(Code::OPEN_FAILED, s.dir,
                              "not a perceptual memory (other files); nothing was changed"));
    case StoreDir::STORE:
      break;
  }
  const auto damage = check_store_log(s.dir);
  if (damage) s.warnings.push_back(damage->to_string());
  // A read-only open must change nothing, so a store LevelDB would rewrite (a read-only mount, or a
  // damaged log tail LevelDB would fold away on replay) is read from a private copy.
  if (mode == OpenMode::READ_ONLY && (!writable_dir(s.dir) || damage)) {
    auto copy = private_copy(s.dir);
    if (!copy) return err(copy.error());
    s.copy = *copy;
  }
  s.read_only = mode == OpenMode::READ_ONLY;
  return false;
}

}  // namespace

Result<PerceptualMemory, MemoryError> PerceptualMemory::open(const std::filesystem::path& dir,
                                                             const MemoryConfig& cfg,
                                                             OpenMode mode) {
  // A bag of words without its dictionary opens a store with the store's own (check_schema).
  const bool adopt = cfg.descriptor.local() && !cfg.descriptor.dictionary;
  if (auto valid = cfg.descriptor.validate(); !valid && !adopt)
    return err(memory_error(Code::OPEN_FAILED, dir, valid.error()));
  auto s = std::make_unique<State>();
  s->dir = dir;
  s->cfg = cfg;
  if (!adopt) s->learner = learner_for(s->cfg);  // else made once the store's words are known
  auto create = prepare(*s, mode);
  if (!create) return err(create.error());
  std::error_code ignored;  // LevelDB creates only the last path component; Open reports failures
  if (*create) std::filesystem::create_directories(dir, ignored);
  leveldb::Options options;
  options.create_if_missing = *create;
  options.paranoid_checks = true;
  leveldb::DB* raw = nullptr;
  const std::filesystem::path where = s->copy.empty() ? dir : s->copy;
  const leveldb::Status st = leveldb::DB::Open(options, where.string(), &raw);
  if (!st.ok()) {
    return err(
        memory_error(st.IsCorruption() ? Code::CORRUPT : Code::OPEN_FAILED, dir, st.ToString()));
  }
  s->db.reset(raw);
  if (auto r = check_schema(*s, *create); !r) { return err(r.error()); }
  if (auto r = load(*s); !r) { return err(r.error()); }
  return PerceptualMemory(std::move(s));
}

PerceptualMemory::PerceptualMemory(std::unique_ptr<State> state) noexcept
    : state_(std::move(state)) {}
PerceptualMemory::PerceptualMemory(PerceptualMemory&&) noexcept = default;
PerceptualMemory& PerceptualMemory::operator=(PerceptualMemory&&) noexcept = default;
PerceptualMemory::~PerceptualMemory() = default;

const Learner& PerceptualMemory::learner() const noexcept { return *state_->learner; }
const MemoryConfig& PerceptualMemory::config() const noexcept { return state_->cfg; }
const std::vector<std::string>& PerceptualMemory::open_warnings() const noexcept {
  return state_->warnings;
}

Result<std::vector<ViewRecord>, MemoryError> PerceptualMemory::views_of(CategoryId id) const {
  return State::read_views(*state_, id);
}

std::vector<CategoryEntry> PerceptualMemory::list() const {
  std::vector<CategoryEntry> out;
  for (const IndexedCategory& c : state_->index) {
    out.push_back(CategoryEntry{c.id, c.record.label, c.record.views});
  }
  return out;
}

MemoryStats PerceptualMemory::stats() const {
  MemoryStats m;
  m.categories = state_->index.size();
  for (const IndexedCategory& c : state_->index) { m.views += c.record.views; }
  m.writes = state_->writes;
  m.learner = state_->learner->stats();
  return m;
}

}  // namespace orthoflow::learning
