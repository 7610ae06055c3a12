#pragma once
/// @file
/// @brief The learning channel across processes: the iceoryx payloads a standalone `orthoflow ui`
/// (or any local program) and a graph run with `--ipc-learning` exchange (docs/IPC.md):
/// - `orthoflow/<graph>/learning_commands`: LearningCommandPayload, one per action;
/// - `orthoflow/<graph>/learning_acks`: LearningAckPayload, every command's answer, for every
///   sender (each takes the ones with its own `client` id);
/// - `orthoflow/<graph>/status`: StatusPayload, the memory's categories and the engine's telemetry,
///   a few times a second.
/// Fixed-size PODs with the header every payload has (type id, version, payload_bytes at offset
/// 48). Both ends decode with the functions below, which check every field another process could
/// have got wrong (kind, lengths, labels by core::check_label, counts): nothing reaches the learner
/// or the page that the teaching UI's HTTP API would have refused.
#include <cstddef>
#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "core/fixed_text.hpp"
#include "core/result.hpp"
#include "graphs/channels/learning_channel.hpp"

namespace orthoflow::graphs {

inline constexpr std::uint32_t LEARNING_COMMAND_TYPE_ID = 0x434C464FU;  ///< "OFLC"
inline constexpr std::uint32_t LEARNING_ACK_TYPE_ID = 0x414C464FU;      ///< "OFLA"
inline constexpr std::uint32_t STATUS_TYPE_ID = 0x5453464FU;            ///< "OFST"
inline constexpr std::uint16_t LEARNING_IPC_VERSION = 1;

/// @brief One action. `client` names the sender (any value unlikely to be another's: a random
/// number per process), `request` its actions (1, 2, ...); the ack carries both back.
struct alignas(64) LearningCommandPayload {
  std::uint32_t type_id;
  std::uint16_t version;
  std::uint16_t reserved0;
  std::uint32_t kind;  ///< LearningCommand::Kind
  std::uint32_t track_id;
  std::uint64_t client;
  std::uint64_t request;
  float position[3];  ///< TEACH by position: sensor frame, metres
  std::uint32_t by_position;
  std::uint64_t payload_bytes;  ///< offset 48: sizeof(LearningCommandPayload)
  std::uint64_t reserved1;
  core::Text label;  ///< zero-terminated
};
static_assert(offsetof(LearningCommandPayload, payload_bytes) == 48);
static_assert(sizeof(LearningCommandPayload) == 128);

/// @brief How the graph's bridge answered a command.
enum class AckStatus : std::uint32_t {
  ACKNOWLEDGED,  ///< outcome and the rest hold the learning channel's answer
  QUEUE_FULL,    ///< the learning channel's queue was full: nothing was done, send again
  INVALID,       ///< the command failed validation (kind, label): nothing was done
  TIMEOUT,       ///< the graph did not answer in time (it may be stopping)
};

/// @brief One command's answer.
struct alignas(64) LearningAckPayload {
  std::uint32_t type_id;
  std::uint16_t version;
  std::uint16_t reserved0;
  std::uint32_t status;   ///< AckStatus
  std::uint32_t outcome;  ///< LearningAck::Outcome (status ACKNOWLEDGED)
  std::uint64_t client;
  std::uint64_t request;
  std::uint32_t kind;  ///< LearningCommand::Kind
  std::uint32_t track_id;
  std::uint32_t views;
  std::uint32_t unknown;
  std::uint64_t payload_bytes;  ///< offset 48: sizeof(LearningAckPayload)
  std::uint64_t frame_id;
  float score;
  float runner_up_score;
  std::uint32_t problem;  ///< status INVALID: core::LabelProblem, or 255 for a bad kind
  std::uint32_t reserved1;
  std::uint64_t reserved2[2];
  core::Text label;
  core::Text nearest;
  core::Text runner_up;
};
static_assert(offsetof(LearningAckPayload, payload_bytes) == 48);
static_assert(sizeof(LearningAckPayload) == 320);

/// @brief Categories and nodes a StatusPayload holds at most (more are counted, not listed).
inline constexpr std::uint32_t STATUS_MAX_CATEGORIES = 128;
inline constexpr std::uint32_t STATUS_MAX_NODES = 32;

struct StatusCategory {
  core::Text label;
  std::uint64_t views;
};
struct StatusNode {
  core::Text name;
  std::uint64_t processed, dropped, deadline_misses;
  std::int64_t p50_ns, p99_ns, max_ns;
};

/// @brief The graph's memory and telemetry.
struct alignas(64) StatusPayload {
  std::uint32_t type_id;
  std::uint16_t version;
  std::uint16_t reserved0;
  std::uint32_t durable;  ///< 1: acknowledged teaches are on disk (--db)
  std::uint32_t category_count;
  std::uint64_t frames_done;
  std::uint64_t drops;
  std::int64_t frame_p99_ns;
  std::uint32_t node_count;
  std::uint32_t categories_total;  ///< the memory's categories (category_count lists the first)
  std::uint64_t payload_bytes;     ///< offset 48: sizeof(StatusPayload)
  std::int64_t published_ns;       ///< steady clock of the graph's host
  StatusCategory categories[STATUS_MAX_CATEGORIES];
  StatusNode nodes[STATUS_MAX_NODES];
};
static_assert(offsetof(StatusPayload, payload_bytes) == 48);

/// @brief A command as the learning channel takes it, with its sender's ids.
struct RemoteCommand {
  std::uint64_t client = 0, request = 0;
  LearningCommand command;
};

/// @brief Why a command payload was refused: `problem` as in LearningAckPayload, and the words.
struct CommandProblem {
  std::uint64_t client = 0, request = 0;  ///< when the payload was whole enough to name them
  std::uint32_t problem = 0;
  std::string message;
};

/// @brief Writes @p command (kind, track, label, position) into @p out. @return false when the
/// label does not pass core::check_label (TEACH, CORRECT, FORGET) — nothing to send.
[[nodiscard]] bool encode_command(const LearningCommand& command, std::uint64_t client,
                                  std::uint64_t request, LearningCommandPayload& out) noexcept;
/// @brief Reads a command another process wrote. @p bytes is the whole sample (header checked
/// already or not: every field is checked here). Errors: short or wrong header, unknown kind,
/// label not zero-terminated or failing core::check_label where the kind needs one, position not
/// finite.
[[nodiscard]] Result<RemoteCommand, CommandProblem> decode_command(
    std::span<const std::byte> bytes);

/// @brief What the other side gets back.
struct RemoteAck {
  std::uint64_t client = 0, request = 0;
  AckStatus status = AckStatus::TIMEOUT;
  std::uint32_t problem = 0;
  LearningAck ack;  ///< kind, outcome, track, views, labels, score, frame (status ACKNOWLEDGED)
};
void encode_ack(const RemoteAck& ack, LearningAckPayload& out) noexcept;
/// @brief Errors (a message): short or wrong header, status or outcome or kind out of range, a
/// text not zero-terminated.
[[nodiscard]] Result<RemoteAck, std::string> decode_ack(std::span<const std::byte> bytes);

/// @brief The status as the page shows it.
struct RemoteStatus {
  bool durable = false;
  std::uint64_t frames_done = 0, drops = 0;
  std::int64_t frame_p99_ns = 0, published_ns = 0;
  std::uint32_t categories_total = 0;
  std::vector<StatusCategory> categories;
  std::vector<StatusNode> nodes;
};
/// @brief Errors: short or wrong header, counts above the capacities, a text not zero-terminated.
[[nodiscard]] Result<RemoteStatus, std::string> decode_status(std::span<const std::byte> bytes);

/// @brief Writes the header fields (type, version, payload_bytes) of each payload.
void reset_header(LearningCommandPayload& p) noexcept;
void reset_header(LearningAckPayload& p) noexcept;
void reset_header(StatusPayload& p) noexcept;

/// @brief Topic names for graph @p graph: orthoflow/<graph>/learning_commands, .../learning_acks,
/// .../status.
[[nodiscard]] std::string learning_commands_topic(const std::string& graph);
[[nodiscard]] std::string learning_acks_topic(const std::string& graph);
[[nodiscard]] std::string status_topic(const std::string& graph);

}  // namespace orthoflow::graphs
