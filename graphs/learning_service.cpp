#include "graphs/learning_service.hpp"

#include <algorithm>
#include <chrono>
#include <vector>

namespace orthoflow::graphs {

namespace {
constexpr std::size_t JOB_VIEWS = 8;  // views one durable teach carries at most
constexpr auto WORKER_POLL = std::chrono::milliseconds(2);
}  // namespace

/// A durable teach waiting for the background writer; fixed size so queueing never allocates.
struct LearningService::Job {
  Text label;
  std::uint32_t track_id = 0;
  std::int64_t stamp_ns = 0;
  std::size_t views = 0;
  std::array<float, JOB_VIEWS * MAX_DESCRIPTOR> values{};
};

learning::MemoryConfig live_session_memory_config() noexcept {
  learning::MemoryConfig cfg;
  cfg.instance.normalise = false;
  cfg.instance.classification_threshold = DEFAULT_NN_THRESHOLD;
  return cfg;
}

Result<std::unique_ptr<LearningService>, std::string> LearningService::open(const LearningSettings& settings) {
  std::unique_ptr<LearningService> s(new LearningService());
  learning::MemoryConfig cfg = settings.memory;
  if (auto valid = cfg.descriptor.validate(); !valid) return err("learning: " + valid.error());
  s->length_ = cfg.descriptor.length();
  if (s->length_ > MAX_DESCRIPTOR) return err("learning: " + cfg.descriptor.describe() + " does not fit the frame block");
  if (settings.db) {
    auto memory = learning::PerceptualMemory::open(*settings.db, cfg);
    if (!memory) return err("learning: " + memory.error().to_string());
    s->memory_ = std::make_unique<learning::PerceptualMemory>(std::move(*memory));
    s->jobs_ = std::make_unique<Job[]>(JOBS);
    s->worker_ = std::thread([raw = s.get()] { raw->worker_loop(); });
  } else if (cfg.learner == learning::LearnerKind::BAYES) {
    cfg.bayes.descriptor_length = s->length_;
    s->learner_ = std::make_unique<learning::BayesLearner>(cfg.bayes);
  } else {
    cfg.instance.descriptor_length = s->length_;
    s->learner_ = std::make_unique<learning::InstanceLearner>(cfg.instance);
  }
  return s;
}

LearningService::~LearningService() {
  stop_.store(true);
  if (worker_.joinable()) worker_.join();
}

const learning::Learner& LearningService::learner() const noexcept {
  return memory_ ? memory_->learner() : *learner_;
}

bool LearningService::teach(std::string_view label, std::span<const float> views, std::uint32_t track_id,
                            std::int64_t stamp_ns) noexcept {
  const std::size_t count = views.size() / length_;
  if (!learning::validate_label(label) || count == 0) {
    refused_.fetch_add(1);
    return false;
  }
  if (!memory_) {
    auto taught = learner_->teach(label, {views.first(count * length_), length_});
    (taught ? teaches_ : refused_).fetch_add(1);
    return taught.has_value();
  }
  const std::size_t head = job_head_.load(std::memory_order_relaxed);
  if (head - job_tail_.load(std::memory_order_acquire) == JOBS) {
    refused_.fetch_add(1);  // the writer is behind: refuse rather than wait
    return false;
  }
  Job& job = jobs_[head % JOBS];
  job.label.assign(label);
  job.track_id = track_id;
  job.stamp_ns = stamp_ns;
  job.views = std::min(count, JOB_VIEWS);
  std::copy_n(views.begin(), job.views * length_, job.values.begin());
  job_head_.store(head + 1, std::memory_order_release);
  return true;
}

// Background writer of durable teaches: the synced LevelDB batch happens here, off the frame path.
void LearningService::worker_loop() noexcept {
  std::vector<learning::ViewRecord> records;
  while (true) {
    const std::size_t tail = job_tail_.load(std::memory_order_relaxed);
    if (tail == job_head_.load(std::memory_order_acquire)) {
      if (stop_.load()) return;
      std::this_thread::sleep_for(WORKER_POLL);
      continue;
    }
    const Job& job = jobs_[tail % JOBS];
    records.assign(job.views, {});
    for (std::size_t v = 0; v < job.views; ++v) {
      records[v].descriptor.assign(job.values.begin() + static_cast<std::ptrdiff_t>(v * length_),
                                   job.values.begin() + static_cast<std::ptrdiff_t>((v + 1) * length_));
      records[v].track_id = job.track_id;
      records[v].stamp_ns = job.stamp_ns;
    }
    auto taught = memory_->teach(job.label.view(), records);
    (taught ? teaches_ : refused_).fetch_add(1);
    job_tail_.store(tail + 1, std::memory_order_release);
  }
}

void LearningService::flush() noexcept {
  while (memory_ && job_tail_.load() != job_head_.load()) std::this_thread::sleep_for(WORKER_POLL);
}

bool LearningService::post(const LearningEvent& event) noexcept {
  const std::size_t head = event_head_.load(std::memory_order_relaxed);
  if (head - event_tail_.load(std::memory_order_acquire) == EVENTS) return false;
  events_[head % EVENTS] = event;
  event_head_.store(head + 1, std::memory_order_release);
  return true;
}

bool LearningService::poll(LearningEvent& event) noexcept {
  const std::size_t tail = event_tail_.load(std::memory_order_relaxed);
  if (tail == event_head_.load(std::memory_order_acquire)) return false;
  event = events_[tail % EVENTS];
  event_tail_.store(tail + 1, std::memory_order_release);
  return true;
}

}  // namespace orthoflow::graphs
