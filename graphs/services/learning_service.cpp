#include "graphs/services/learning_service.hpp"

#include <algorithm>
#include <chrono>
#include <vector>

namespace orthoflow::graphs {

namespace {
constexpr std::size_t JOBS = 16;  // durable writes in flight at most
constexpr auto WORKER_POLL = std::chrono::milliseconds(2);
using Outcome = LearningAck::Outcome;
}  // namespace

/// A durable teach or forget waiting for the background writer; fixed size so queueing never
/// allocates. Its views wait in the service's job_values_, in its ring slot's room (job_values()).
struct LearningService::Job {
  enum class Kind : std::uint8_t { TEACH, FORGET, UNDO };
  Kind kind = Kind::TEACH;
  Text label;
  std::uint32_t track_id = 0;
  std::int64_t stamp_ns = 0;
  std::size_t views = 0;
  LearningAck ack;  // sent after the write (sequence 0: nobody to tell)
};

float default_nn_threshold(const kernels::DescriptorSpec& spec) noexcept {
  return spec.kind == kernels::DescriptorKind::SPIN_SET ? DEFAULT_SPIN_NN_THRESHOLD
                                                        : DEFAULT_NN_THRESHOLD;
}

learning::MemoryConfig live_session_memory_config() noexcept {
  learning::MemoryConfig cfg;
  cfg.instance.normalise = false;
  cfg.instance.classification_threshold = DEFAULT_NN_THRESHOLD;
  return cfg;
}

LearningService::LearningService() : jobs_(JOBS) {}

Result<std::unique_ptr<LearningService>, std::string> LearningService::open(
    const LearningSettings& settings) {
  std::unique_ptr<LearningService> s(new LearningService());
  learning::MemoryConfig cfg = settings.memory;
  if (auto valid = cfg.descriptor.validate(); !valid) return err("learning: " + valid.error());
  s->spec_ = cfg.descriptor;
  const std::size_t length = cfg.descriptor.length();
  s->history_ = std::make_unique<LessonHistory>(MAX_UNDO_LESSONS, MAX_TEACH_VIEWS * length);
  if (settings.db) {
    auto memory = learning::PerceptualMemory::open(*settings.db, cfg);
    if (!memory) return err("learning: " + memory.error().to_string());
    s->memory_ = std::make_unique<learning::PerceptualMemory>(std::move(*memory));
    s->job_values_.assign(JOBS * MAX_TEACH_VIEWS * length, 0.0F);
    s->worker_ = std::thread([raw = s.get()] { raw->worker_loop(); });
  } else {
    s->learner_ = learning::make_learner(cfg.descriptor, cfg.learner, cfg.instance, cfg.bayes);
  }
  return s;
}

LearningService::~LearningService() {
  stop_.store(true);
  if (worker_.joinable()) worker_.join();
}

const std::vector<std::string>& LearningService::open_warnings() const noexcept {
  static const std::vector<std::string> NONE;
  return memory_ ? memory_->open_warnings() : NONE;
}

const learning::Learner& LearningService::learner() const noexcept {
  return memory_ ? memory_->learner() : *learner_;
}

LearningAck LearningService::finish(LearningAck ack, bool ok, Outcome failure) noexcept {
  ack.outcome = ok ? (memory_ ? Outcome::STORED : Outcome::LEARNED) : failure;
  if (!ok) {
    refused_.fetch_add(1);
  } else if (ack.kind != LearningCommand::Kind::FORGET && ack.kind != LearningCommand::Kind::UNDO) {
    teaches_.fetch_add(1);
  }
  if (ack.sequence != 0) acknowledge(ack);
  return ack;
}

LearningAck LearningService::teach(std::string_view label, std::span<const float> views,
                                   std::uint32_t track_id, std::int64_t stamp_ns,
                                   LearningAck ack) noexcept {
  const std::size_t length = descriptor_length();
  const std::size_t count = std::min(views.size() / length, MAX_TEACH_VIEWS);
  ack.track_id = track_id;
  ack.views = static_cast<std::uint32_t>(count);
  ack.label.assign(label);
  if (!learning::validate_label(label)) return finish(ack, false, Outcome::BAD_LABEL);
  if (count == 0) return finish(ack, false, Outcome::REJECTED);
  const auto taught_values = views.first(count * length);
  if (!memory_) {
    const bool taught = learner_->teach(label, {taught_values, length}).has_value();
    if (taught) history_->push(label, taught_values);
    return finish(ack, taught, Outcome::REJECTED);
  }
  Job* job = jobs_.claim();
  if (job == nullptr)
    return finish(ack, false, Outcome::BUSY);  // the writer is behind: refuse, never wait
  history_->push(label, taught_values);        // a write that fails later makes its undo refused
  job->kind = Job::Kind::TEACH;
  job->label.assign(label);
  job->track_id = track_id;
  job->stamp_ns = stamp_ns;
  job->views = count;
  job->ack = ack;
  std::copy_n(views.begin(), count * length, job_values(*job).begin());
  jobs_.publish();
  ack.outcome = Outcome::STORED;  // on its way: the writer acknowledges after the synced write
  return ack;
}

LearningAck LearningService::forget(std::string_view label, LearningAck ack) noexcept {
  ack.label.assign(label);
  if (!memory_) {
    const bool forgotten = learner_->forget(label).has_value();
    if (forgotten) history_->drop(label);
    return finish(ack, forgotten, Outcome::UNKNOWN_LABEL);
  }
  Job* job = jobs_.claim();
  if (job == nullptr) return finish(ack, false, Outcome::BUSY);
  history_->drop(label);
  job->kind = Job::Kind::FORGET;
  job->label.assign(label);
  job->views = 0;
  job->ack = ack;
  jobs_.publish();
  ack.outcome = Outcome::STORED;
  return ack;
}

LearningAck LearningService::undo(LearningAck ack) noexcept {
  LessonHistory::Lesson lesson;
  ack.track_id = 0;
  if (!history_->newest(lesson)) return finish(ack, false, Outcome::NOTHING_TO_UNDO);
  const std::size_t length = descriptor_length();
  ack.label.assign(lesson.label);
  ack.views = static_cast<std::uint32_t>(lesson.values.size() / length);
  if (!memory_) {
    const bool undone = learner_->retract(lesson.label, {lesson.values, length}).has_value();
    history_->pop();
    return finish(ack, undone, Outcome::NOTHING_TO_UNDO);
  }
  Job* job = jobs_.claim();
  if (job == nullptr) return finish(ack, false, Outcome::BUSY);  // the lesson stays undoable
  job->kind = Job::Kind::UNDO;
  job->label.assign(lesson.label);
  job->views = ack.views;
  job->ack = ack;
  std::copy(lesson.values.begin(), lesson.values.end(), job_values(*job).begin());
  jobs_.publish();
  history_->pop();
  ack.outcome = Outcome::STORED;
  return ack;
}

// Every ring slot has its own room in job_values_; whoever holds the slot's job holds the room.
std::span<float> LearningService::job_values(const Job& job) noexcept {
  const std::size_t room = MAX_TEACH_VIEWS * descriptor_length();
  return std::span<float>(job_values_).subspan(jobs_.slot_of(&job) * room, room);
}

// One durable write, then its acknowledgement (only now is the lesson on disk and visible to asks).
void LearningService::run_job(const Job& job) noexcept {
  LearningAck ack = job.ack;
  const std::size_t length = descriptor_length();
  if (job.kind == Job::Kind::UNDO) {
    const auto values = job_values(job).first(job.views * length);
    auto undone = memory_->retract(job.label.view(), {values, length});
    const bool failed = !undone && undone.error().code == learning::MemoryError::Code::WRITE_FAILED;
    finish(ack, undone.has_value(), failed ? Outcome::WRITE_FAILED : Outcome::NOTHING_TO_UNDO);
    return;
  }
  if (job.kind == Job::Kind::FORGET) {
    auto forgotten = memory_->forget(job.label.view());
    const bool unknown =
        !forgotten && forgotten.error().code == learning::MemoryError::Code::UNKNOWN_LABEL;
    finish(ack, forgotten.has_value(), unknown ? Outcome::UNKNOWN_LABEL : Outcome::WRITE_FAILED);
    return;
  }
  std::vector<learning::ViewRecord> records(job.views);  // the writer thread may allocate
  const auto values = job_values(job);
  for (std::size_t v = 0; v < job.views; ++v) {
    const auto view = values.subspan(v * length, length);
    records[v].descriptor.assign(view.begin(), view.end());
    records[v].track_id = job.track_id;
    records[v].stamp_ns = job.stamp_ns;
  }
  auto taught = memory_->teach(job.label.view(), records);
  const bool rejected = !taught && taught.error().code == learning::MemoryError::Code::REJECTED;
  finish(ack, taught.has_value(), rejected ? Outcome::REJECTED : Outcome::WRITE_FAILED);
}

// Background writer of durable lessons: the synced LevelDB batch happens here, off the frame path.
void LearningService::worker_loop() noexcept {
  while (true) {
    const Job* job = jobs_.peek();
    if (job == nullptr) {
      if (stop_.load()) return;
      std::this_thread::sleep_for(WORKER_POLL);
      continue;
    }
    run_job(*job);
    jobs_.release(1);
  }
}

void LearningService::flush() noexcept {
  while (memory_ && jobs_.size() != 0) std::this_thread::sleep_for(WORKER_POLL);
}

}  // namespace orthoflow::graphs
