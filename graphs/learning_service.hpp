#pragma once
/// @file
/// @brief LearningService: what the tabletop graph asks and teaches. Wraps an in-memory learner or a
/// durable PerceptualMemory (LevelDB), and carries the learning events that enter the graph from
/// outside (a person teaching or correcting by track id or by pointing at a position).
///
/// Real time: ask() is lock-free and allocation-free (the learner's snapshot read). A teach from the
/// frame path is applied inline for an in-memory learner (a snapshot rebuild: it allocates, once per
/// teach) and handed to a background thread for a durable memory, so the frame path never waits for a
/// synced disk write; the teach becomes visible to the asks after that write (a few frames later).
#include <array>
#include <atomic>
#include <cstdint>
#include <filesystem>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <thread>

#include "graphs/frame_block.hpp"
#include "learning/perceptual_memory.hpp"

namespace orthoflow::graphs {

/// @brief A learning event from outside the graph.
struct LearningEvent {
  enum class Kind : std::uint8_t { TEACH_TRACK, TEACH_AT } kind = Kind::TEACH_TRACK;
  std::uint32_t track_id = 0;         ///< TEACH_TRACK: the object with this track id
  std::array<float, 3> position{};    ///< TEACH_AT: the object whose box holds (or is nearest to) it
  Text label;
};

/// @brief The live-session default: plain nearest neighbour over GOOD (L2), Unknown beyond this
/// distance. A category taught from a few views of one still object has an ICD near zero, which makes
/// the thesis's NOCD explode for every other instance; docs/TABLETOP.md has the measurements.
inline constexpr float DEFAULT_NN_THRESHOLD = 0.3F;

/// @brief The in-memory learner settings `orthoflow run` starts from (instance-based, plain NN).
[[nodiscard]] learning::MemoryConfig live_session_memory_config() noexcept;

/// @brief Learner settings of a service.
struct LearningSettings {
  learning::MemoryConfig memory = live_session_memory_config();  ///< descriptor, learner kind, settings
  std::optional<std::filesystem::path> db;  ///< durable memory directory; none = in memory only
};

/// @brief Learning for one graph. @note ask() and drain() are for the recognise node (one thread at a
/// time); post() is for one other thread (single producer); teach() for the recognise node.
class LearningService {
 public:
  /// @brief Opens the memory (or makes an in-memory learner). Errors name the store and the reason.
  [[nodiscard]] static Result<std::unique_ptr<LearningService>, std::string> open(const LearningSettings& settings);
  ~LearningService();
  LearningService(const LearningService&) = delete;
  LearningService& operator=(const LearningService&) = delete;

  [[nodiscard]] const learning::Learner& learner() const noexcept;
  [[nodiscard]] std::size_t descriptor_length() const noexcept { return length_; }
  /// @brief Teaches @p views (row-major, descriptor_length() each) under @p label.
  /// @return false if refused (bad label or view) or the background queue is full (counted).
  bool teach(std::string_view label, std::span<const float> views, std::uint32_t track_id, std::int64_t stamp_ns) noexcept;
  /// @brief Queues an outside event; false if the queue is full. Lock-free.
  bool post(const LearningEvent& event) noexcept;
  /// @brief Takes the next queued event, if any. Lock-free.
  bool poll(LearningEvent& event) noexcept;
  /// @brief Waits until every queued durable teach is written (tests, shutdown).
  void flush() noexcept;
  [[nodiscard]] std::uint64_t teaches() const noexcept { return teaches_.load(); }
  [[nodiscard]] std::uint64_t refused() const noexcept { return refused_.load(); }

 private:
  struct Job;
  LearningService() = default;
  void worker_loop() noexcept;

  std::unique_ptr<learning::Learner> learner_;               // in memory
  std::unique_ptr<learning::PerceptualMemory> memory_;       // durable
  std::size_t length_ = 0;
  static constexpr std::size_t EVENTS = 64, JOBS = 16;
  std::array<LearningEvent, EVENTS> events_{};
  std::atomic<std::size_t> event_head_{0}, event_tail_{0};
  std::unique_ptr<Job[]> jobs_;
  std::atomic<std::size_t> job_head_{0}, job_tail_{0};
  std::atomic<bool> stop_{false};
  std::atomic<std::uint64_t> teaches_{0}, refused_{0};
  std::thread worker_;
};

}  // namespace orthoflow::graphs
