// teach / correct / forget of the perceptual memory: one synced leveldb::WriteBatch per call, and
// the learner is updated only after that write returned (acknowledged = durable, docs/LEARNING.md).
#include <leveldb/write_batch.h>

#include <algorithm>
#include <cmath>

#include "learning/detail/memory_state.hpp"
#include "learning/perceptual_memory.hpp"

namespace orthoflow::learning {

using Code = MemoryError::Code;

Result<void, MemoryError> write_synced(PerceptualMemory::State& s, leveldb::WriteBatch& batch,
                                       const std::string& what) {
  if (s.read_only) {
    return err(
        memory_error(Code::READ_ONLY, s.dir, what + ": opened read-only, nothing was written"));
  }
  leveldb::WriteOptions sync;
  sync.sync = true;  // fsync before returning: a crash after this point cannot lose the batch
  const leveldb::Status st = s.db->Write(sync, &batch);
  if (!st.ok()) {
    return err(memory_error(Code::WRITE_FAILED, s.dir, what + ": " + st.ToString()));
  }
  ++s.writes;
  return {};
}

namespace {

bool all_finite(std::span<const float> values) noexcept {
  return std::all_of(values.begin(), values.end(), [](float v) { return std::isfinite(v); });
}

// What the store cannot hold (an export writes JSON, which has no NaN or infinity) or should not
// (a view whose descriptor is all zeros: no point fell in any projection), as a sentence; null when
// the view is fine.
const char* view_problem(const ViewRecord& v, ViewSource source) noexcept {
  if (!all_finite(v.frame)) { return "its object frame is not finite"; }
  if (!all_finite(v.bbox)) { return "its bounding box is not finite"; }
  const bool empty =
      std::all_of(v.descriptor.begin(), v.descriptor.end(), [](float x) { return x == 0.0F; });
  if (empty && source == ViewSource::TEACH) {
    return "its descriptor is all zeros (an empty view: no point fell in any projection)";
  }
  return nullptr;
}

// Every check the learner would make, done before anything is written, so a refused teach leaves
// both the store and the learner untouched.
Result<std::vector<float>, MemoryError> checked_values(const PerceptualMemory::State& s,
                                                       std::string_view label,
                                                       std::span<const ViewRecord> views,
                                                       ViewSource source) {
  const std::string what = "teach \"" + std::string(label.substr(0, LABEL_MAX_BYTES)) + "\"";
  if (auto r = validate_label(label); !r) {
    return err(memory_error(Code::REJECTED, s.dir, what + ": " + to_string(r.error())));
  }
  const std::size_t length = s.learner->descriptor_length();
  std::vector<float> flat;
  for (std::size_t v = 0; v < views.size(); ++v) {
    const auto& d = views[v].descriptor;
    if (auto r = validate_batch(DescriptorBatch{d, length}, length, true); !r) {
      return err(memory_error(Code::REJECTED, s.dir,
                              what + ": view " + std::to_string(v) + ": " + to_string(r.error()) +
                                  " (" + std::to_string(d.size()) + " values, expected " +
                                  std::to_string(length) + ")"));
    }
    if (const char* problem = view_problem(views[v], source)) {
      return err(memory_error(Code::REJECTED, s.dir,
                              what + ": view " + std::to_string(v) + ": " + problem));
    }
    flat.insert(flat.end(), d.begin(), d.end());
  }
  if (flat.empty()) {
    return err(memory_error(Code::REJECTED, s.dir, what + ": " + to_string(LearnError::NO_VIEWS)));
  }
  return flat;
}

}  // namespace

Result<StagedTeach, MemoryError> stage_teach(PerceptualMemory::State& s, std::string_view label,
                                             std::span<const ViewRecord> views, CategoryId& next_id,
                                             leveldb::WriteBatch& batch, ViewSource source) {
  auto flat_result = checked_values(s, label, views, source);
  if (!flat_result) { return err(flat_result.error()); }
  const std::size_t length = s.learner->descriptor_length();
  const IndexedCategory* existing = s.find(label);
  StagedTeach staged{existing != nullptr
                         ? *existing
                         : IndexedCategory{next_id, {0, 0, std::string(label)}, {0, {}}},
                     existing == nullptr, std::move(*flat_result)};
  IndexedCategory& next = staged.next;
  if (staged.fresh) ++next_id;
  if (next.model.sums.empty()) { next.model.sums.assign(length, 0.0); }
  for (const ViewRecord& v : views) {
    batch.Put(view_key(next.id, next.record.next_seq++), encode_view(v, s.cfg.descriptor));
  }
  next.record.views += static_cast<std::uint32_t>(views.size());
  // Thesis Bayes update a_k <- a_k + x' in the same batch as the views, so model and views never
  // disagree.
  accumulate_views(DescriptorBatch{staged.values, length}, next.model.sums);
  next.model.seen += views.size();
  batch.Put(category_key(KIND_CATEGORY, next.id), encode_category(next.record));
  batch.Put(category_key(KIND_MODEL, next.id), encode_model(next.model));
  return staged;
}

void apply_staged(PerceptualMemory::State& s, const StagedTeach& staged) {
  // Durable from here on: update the index, then the learner (which publishes the snapshot for
  // ask()).
  const std::string& label = staged.next.record.label;
  if (staged.fresh) {
    s.next_id = std::max(s.next_id, staged.next.id + 1);
    s.index.push_back(staged.next);
  } else {
    *s.find(label) = staged.next;
  }
  const DescriptorBatch views{staged.values, s.learner->descriptor_length()};
  const auto learned = s.learner->teach(label, views);
  OF_ENFORCE(learned.has_value() && *learned == staged.next.id,
             "learner and memory disagree on a category id");
}

Result<CategoryId, MemoryError> PerceptualMemory::teach(std::string_view label,
                                                        std::span<const ViewRecord> views) {
  State& s = *state_;
  leveldb::WriteBatch batch;
  CategoryId next_id = s.next_id;
  auto staged = stage_teach(s, label, views, next_id, batch);
  if (!staged) return err(staged.error());
  if (staged->fresh) batch.Put(std::string(KEY_NEXT_ID), encode_u32(next_id));
  if (auto r = write_synced(s, batch, "teach \"" + std::string(label) + "\""); !r) {
    return err(r.error());
  }
  apply_staged(s, *staged);
  return staged->next.id;
}

Result<CategoryId, MemoryError> PerceptualMemory::correct(std::string_view label,
                                                          const ViewRecord& view) {
  return teach(label, std::span<const ViewRecord>(&view, 1));
}

namespace {

// The keys of the last @p n views of category @p id, oldest first, with their descriptors
// compared to @p views: REJECTED unless they are exactly those views.
Result<std::vector<std::string>, MemoryError> last_view_keys(PerceptualMemory::State& s,
                                                             CategoryId id, DescriptorBatch views,
                                                             const std::string& what) {
  std::vector<std::string> keys;
  std::vector<ViewRecord> records;
  const std::string prefix = category_key(KIND_VIEW, id);
  std::unique_ptr<leveldb::Iterator> it(s.db->NewIterator(leveldb::ReadOptions()));
  for (it->Seek(prefix); it->Valid() && it->key().starts_with(prefix); it->Next()) {
    std::string why;
    auto view = decode_view(as_view(it->value()), s.cfg.descriptor, why);
    if (!view) return err(memory_error(Code::CORRUPT, s.dir, what + ": " + why));
    keys.emplace_back(it->key().ToString());
    records.push_back(std::move(*view));
  }
  const std::size_t n = views.count();
  if (n > records.size()) {
    return err(memory_error(Code::REJECTED, s.dir,
                            what + ": " + std::to_string(n) + " views asked back, " +
                                std::to_string(records.size()) + " stored"));
  }
  const std::size_t first = records.size() - n;
  for (std::size_t v = 0; v < n; ++v) {
    const std::span<const float> want = views.view(v);
    const std::vector<float>& have = records[first + v].descriptor;
    if (!std::equal(want.begin(), want.end(), have.begin(), have.end())) {
      return err(memory_error(Code::REJECTED, s.dir,
                              what + ": the stored views differ from the ones to take back " +
                                  "(a later lesson or another writer changed the category)"));
    }
  }
  keys.erase(keys.begin(), keys.begin() + static_cast<std::ptrdiff_t>(first));
  return keys;
}

}  // namespace

Result<void, MemoryError> PerceptualMemory::retract(std::string_view label, DescriptorBatch views) {
  State& s = *state_;
  const std::string what = "undo \"" + std::string(label.substr(0, LABEL_MAX_BYTES)) + "\"";
  IndexedCategory* c = s.find(label);
  if (c == nullptr) {
    return err(memory_error(Code::UNKNOWN_LABEL, s.dir, what + ": no such category"));
  }
  const std::size_t length = s.learner->descriptor_length();
  if (auto r = validate_batch(views, length, false); !r) {
    return err(memory_error(Code::REJECTED, s.dir, what + ": " + to_string(r.error())));
  }
  auto keys = last_view_keys(s, c->id, views, what);
  if (!keys) return err(keys.error());
  IndexedCategory next = *c;
  next.record.views -= static_cast<std::uint32_t>(views.count());
  next.model.seen -= std::min<std::uint64_t>(next.model.seen, views.count());
  subtract_views(views, next.model.sums);
  leveldb::WriteBatch batch;
  for (const std::string& key : *keys) batch.Delete(key);
  const bool emptied = next.record.views == 0;
  if (emptied) {
    batch.Delete(category_key(KIND_CATEGORY, next.id));
    batch.Delete(category_key(KIND_MODEL, next.id));
  } else {
    batch.Put(category_key(KIND_CATEGORY, next.id), encode_category(next.record));
    batch.Put(category_key(KIND_MODEL, next.id), encode_model(next.model));
  }
  if (auto r = write_synced(s, batch, what); !r) return err(r.error());
  const CategoryId id = next.id;
  if (emptied) {
    s.index.erase(std::remove_if(s.index.begin(), s.index.end(),
                                 [id](const IndexedCategory& e) { return e.id == id; }),
                  s.index.end());
  } else {
    *c = std::move(next);
  }
  OF_ENFORCE(s.learner->retract(label, views).has_value(),
             "learner and memory disagree on a category's last views");
  return {};
}

Result<void, MemoryError> PerceptualMemory::forget(std::string_view label) {
  State& s = *state_;
  const IndexedCategory* c = s.find(label);
  if (c == nullptr) {
    return err(memory_error(Code::UNKNOWN_LABEL, s.dir,
                            "forget \"" + std::string(label) + "\": no such category"));
  }
  leveldb::WriteBatch batch;
  const std::string prefix = category_key(KIND_VIEW, c->id);
  std::unique_ptr<leveldb::Iterator> it(s.db->NewIterator(leveldb::ReadOptions()));
  for (it->Seek(prefix); it->Valid() && it->key().starts_with(prefix); it->Next()) {
    batch.Delete(it->key());
  }
  batch.Delete(category_key(KIND_CATEGORY, c->id));
  batch.Delete(category_key(KIND_MODEL, c->id));
  if (auto r = write_synced(s, batch, "forget \"" + std::string(label) + "\""); !r) {
    return err(r.error());
  }
  const CategoryId id = c->id;
  s.index.erase(std::remove_if(s.index.begin(), s.index.end(),
                               [id](const IndexedCategory& e) { return e.id == id; }),
                s.index.end());
  OF_ENFORCE(s.learner->forget(label).has_value(), "learner lost a category the memory holds");
  return {};
}

}  // namespace orthoflow::learning
