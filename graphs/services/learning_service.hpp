#pragma once
/// @file
/// @brief LearningService: what the tabletop graph asks and teaches. Wraps an in-memory learner or
/// a durable PerceptualMemory (LevelDB), and carries the learning channel
/// (graphs/channels/learning_channel.hpp): commands from any number of connected senders in,
/// acknowledgements back to each sender.
///
/// Real time: ask() is lock-free and allocation-free (the learner's snapshot read). A teach,
/// correct or forget from the frame path is applied inline for an in-memory learner (a snapshot
/// rebuild: it allocates, once per lesson) and handed to a background thread for a durable memory,
/// so the frame path never waits for a synced disk write; it becomes visible to the asks, and is
/// acknowledged as STORED, after that write (a few frames later).
#include <array>
#include <atomic>
#include <cstdint>
#include <filesystem>
#include <memory>
#include <mutex>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <thread>
#include <vector>

#include "core/spin_lock.hpp"
#include "core/spsc_ring.hpp"
#include "graphs/channels/learning_channel.hpp"
#include "graphs/frame/frame_block.hpp"
#include "graphs/services/lesson_history.hpp"
#include "learning/perceptual_memory.hpp"

namespace orthoflow::graphs {

/// @brief The live-session default: plain nearest neighbour over GOOD (L2), Unknown beyond this
/// distance. A category taught from a few views of one still object has an ICD near zero, which
/// makes the thesis's NOCD explode for every other instance; docs/TABLETOP.md has the measurements.
inline constexpr float DEFAULT_NN_THRESHOLD = 0.3F;
/// @brief The same for sets of spin images: Unknown beyond this set distance D(T, O). On the
/// embedded session's seeds 1-3 every taught category's views, new instances included, were within
/// 0.114 of their category and the never-taught plate 0.201 or more from any (docs/TABLETOP.md).
inline constexpr float DEFAULT_SPIN_NN_THRESHOLD = 0.15F;
/// @brief DEFAULT_SPIN_NN_THRESHOLD for a set of spin images, else DEFAULT_NN_THRESHOLD.
[[nodiscard]] float default_nn_threshold(const kernels::DescriptorSpec& spec) noexcept;
/// @brief Senders that can be connected at once.
inline constexpr std::size_t MAX_LEARNING_CLIENTS = 8;
/// @brief Views one teach stores at most (a track's key views and its current view).
inline constexpr std::size_t MAX_TEACH_VIEWS = 8;

/// @brief The in-memory learner settings `orthoflow run` starts from (instance-based, plain NN).
[[nodiscard]] learning::MemoryConfig live_session_memory_config() noexcept;

/// @brief Learner settings of a service.
struct LearningSettings {
  learning::MemoryConfig memory =
      live_session_memory_config();         ///< descriptor, learner kind, settings
  std::optional<std::filesystem::path> db;  ///< durable memory directory; none = in memory only
};

class LearningService;

/// @brief One sender's end of the learning channel. Thread-compatible: one thread uses a client;
/// other threads use clients of their own. Disconnects when destroyed. @pre destroyed before its
/// service.
class LearningClient {
 public:
  ~LearningClient();
  LearningClient(const LearningClient&) = delete;
  LearningClient& operator=(const LearningClient&) = delete;
  /// @brief Queues @p command; @return its sequence number (acks carry it), or 0 if the queue is
  /// full.
  std::uint64_t send(LearningCommand command) noexcept;
  /// @brief Takes the next acknowledgement, if any. Lock-free.
  bool poll(LearningAck& ack) noexcept;
  [[nodiscard]] std::uint32_t id() const noexcept { return slot_; }

 private:
  friend class LearningService;
  LearningClient(LearningService& service, std::uint32_t slot) noexcept
      : service_(service), slot_(slot) {}
  LearningService& service_;
  std::uint32_t slot_;
  std::uint64_t next_sequence_ = 1;
};

/// @brief Learning for one graph. @note connect() and LearningClient::send are thread-safe; poll(),
/// ask(), teach(), correct(), forget() and acknowledge() are for the recognise node (one thread at
/// a time).
class LearningService {
 public:
  /// @brief Opens the memory (or makes an in-memory learner). Errors name the store and the reason.
  [[nodiscard]] static Result<std::unique_ptr<LearningService>, std::string> open(
      const LearningSettings& settings);
  ~LearningService();
  LearningService(const LearningService&) = delete;
  LearningService& operator=(const LearningService&) = delete;

  [[nodiscard]] const learning::Learner& learner() const noexcept;
  [[nodiscard]] const kernels::DescriptorSpec& descriptor() const noexcept { return spec_; }
  [[nodiscard]] std::size_t descriptor_length() const noexcept { return spec_.length(); }
  [[nodiscard]] bool durable() const noexcept { return memory_ != nullptr; }
  /// @brief What opening the store found wrong and went on from
  /// (learning::PerceptualMemory::open_warnings()); the caller must show them.
  [[nodiscard]] const std::vector<std::string>& open_warnings() const noexcept;

  /// @brief A new sender, or nullptr when MAX_LEARNING_CLIENTS are connected. Thread-safe.
  [[nodiscard]] std::unique_ptr<LearningClient> connect();
  /// @brief Takes the next queued command, if any. Lock-free.
  bool poll(LearningCommand& command) noexcept;
  /// @brief Delivers @p ack to its sender (dropped if the sender has gone).
  void acknowledge(const LearningAck& ack) noexcept;

  /// @brief Stores @p views (row-major, descriptor_length() each, at most MAX_TEACH_VIEWS) under @p
  /// label. In memory: learned now, @p ack completed (LEARNED or the error) and returned. Durable:
  /// queued, acknowledged (STORED or WRITE_FAILED) by the writer after the synced write; returns
  /// the ack as queued (outcome STORED means "on its way") or BUSY / BAD_LABEL / REJECTED when
  /// refused at once. With @p ack.sequence == 0 (the scripted instructor) nothing is acknowledged.
  LearningAck teach(std::string_view label, std::span<const float> views, std::uint32_t track_id,
                    std::int64_t stamp_ns, LearningAck ack) noexcept;
  /// @brief Forgets @p label; same acknowledgement rules as teach().
  LearningAck forget(std::string_view label, LearningAck ack) noexcept;
  /// @brief Takes back the most recent teach or correct that is not undone yet (of any sender,
  /// the scripted instructor's too; up to MAX_UNDO_LESSONS back; a forget drops its category's
  /// lessons): exactly the views it stored, from the memory too (synced) when durable. @p ack gets
  /// the lesson's label and view count; NOTHING_TO_UNDO when there is none, or when the memory's
  /// last views of the category are not the lesson's. Same acknowledgement rules as teach().
  LearningAck undo(LearningAck ack) noexcept;

  /// @brief Waits until every queued durable write is done (tests, shutdown).
  void flush() noexcept;
  [[nodiscard]] std::uint64_t teaches() const noexcept { return teaches_.load(); }
  [[nodiscard]] std::uint64_t refused() const noexcept { return refused_.load(); }
  [[nodiscard]] std::uint64_t commands_dropped() const noexcept { return commands_dropped_.load(); }
  [[nodiscard]] std::uint64_t acks_dropped() const noexcept { return acks_dropped_.load(); }

 private:
  friend class LearningClient;
  struct Job;
  struct ClientSlot {
    core::SpinLock lock;  // producers of acks: the recognise node and the durable writer
    core::SpscRing<LearningAck> acks{64};
    std::atomic<bool> active{false};
  };
  LearningService();
  void worker_loop() noexcept;
  void run_job(const Job& job) noexcept;
  /// The views' room of @p job's ring slot (the recognise node fills it before publish, the
  /// writer reads it before release).
  [[nodiscard]] std::span<float> job_values(const Job& job) noexcept;
  std::uint64_t enqueue(LearningCommand command) noexcept;
  void disconnect(std::uint32_t slot) noexcept;
  LearningAck finish(LearningAck ack, bool ok, LearningAck::Outcome failure) noexcept;

  std::unique_ptr<learning::Learner> learner_;          // in memory
  std::unique_ptr<learning::PerceptualMemory> memory_;  // durable
  std::unique_ptr<LessonHistory> history_;  // the recognise node's: lessons that undo can take back
  kernels::DescriptorSpec spec_{};
  std::mutex senders_;  // serialises the command producers
  core::SpscRing<LearningCommand> commands_{64};
  std::array<ClientSlot, MAX_LEARNING_CLIENTS> clients_{};
  core::SpscRing<Job> jobs_;  // recognise node -> durable writer
  /// Durable: room for MAX_TEACH_VIEWS views of every job slot (sized once by open()).
  std::vector<float> job_values_;
  std::atomic<bool> stop_{false};
  std::atomic<std::uint64_t> teaches_{0}, refused_{0}, commands_dropped_{0}, acks_dropped_{0};
  std::thread worker_;
};

}  // namespace orthoflow::graphs
