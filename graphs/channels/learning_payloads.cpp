#include "graphs/channels/learning_payloads.hpp"

#include <cmath>
#include <cstring>
#include <memory>
#include <type_traits>

#include "core/label_text.hpp"
#include "graphs/channels/payload_decode.hpp"

namespace orthoflow::graphs {

namespace {

using Kind = LearningCommand::Kind;
using Outcome = LearningAck::Outcome;

/// What INVALID acks carry in `problem` for a kind out of range (core::LabelProblem otherwise).
constexpr std::uint32_t PROBLEM_BAD_KIND = 255;
constexpr std::uint32_t PROBLEM_BAD_POSITION = 254;

template <class Payload>
bool read_whole(std::span<const std::byte> bytes, std::uint32_t type_id, Payload& out,
                std::string& error) {
  return read_whole_payload(bytes, type_id, LEARNING_IPC_VERSION, out, error);
}

// A text another process wrote: zero-terminated within its capacity, else refused.
bool read_text(const core::Text& in, core::Text& out) {
  const std::size_t n = ::strnlen(in.chars.data(), in.chars.size());
  if (n > core::Text::capacity()) return false;
  out.assign(std::string_view(in.chars.data(), n));
  return true;
}

bool needs_label(Kind kind) {
  return kind == Kind::TEACH || kind == Kind::CORRECT || kind == Kind::FORGET;
}

}  // namespace

void reset_header(LearningCommandPayload& p) noexcept {
  reset_payload_header(p, LEARNING_COMMAND_TYPE_ID, LEARNING_IPC_VERSION);
}

void reset_header(LearningAckPayload& p) noexcept {
  reset_payload_header(p, LEARNING_ACK_TYPE_ID, LEARNING_IPC_VERSION);
}

void reset_header(StatusPayload& p) noexcept {
  reset_payload_header(p, STATUS_TYPE_ID, LEARNING_IPC_VERSION);
}

bool encode_command(const LearningCommand& command, std::uint64_t client, std::uint64_t request,
                    LearningCommandPayload& out) noexcept {
  if (needs_label(command.kind) &&
      core::check_label(command.label.view()) != core::LabelProblem::NONE)
    return false;
  reset_header(out);
  out.kind = static_cast<std::uint32_t>(command.kind);
  out.track_id = command.track_id;
  out.client = client;
  out.request = request;
  for (int i = 0; i < 3; ++i) out.position[i] = command.position[static_cast<std::size_t>(i)];
  out.by_position = command.by_position ? 1U : 0U;
  out.label = command.label;
  return true;
}

Result<RemoteCommand, CommandProblem> decode_command(std::span<const std::byte> bytes) {
  LearningCommandPayload p;
  CommandProblem problem;
  if (!read_whole(bytes, LEARNING_COMMAND_TYPE_ID, p, problem.message)) {
    problem.problem = PROBLEM_BAD_KIND;
    return err(std::move(problem));
  }
  problem.client = p.client;
  problem.request = p.request;
  if (p.kind > static_cast<std::uint32_t>(Kind::UNDO)) {
    problem.problem = PROBLEM_BAD_KIND;
    problem.message = "unknown command kind " + std::to_string(p.kind);
    return err(std::move(problem));
  }
  RemoteCommand out;
  out.client = p.client;
  out.request = p.request;
  out.command.kind = static_cast<Kind>(p.kind);
  out.command.track_id = p.track_id;
  out.command.by_position = out.command.kind == Kind::TEACH && p.by_position != 0;
  for (int i = 0; i < 3; ++i) {
    if (out.command.by_position && !std::isfinite(p.position[i])) {
      problem.problem = PROBLEM_BAD_POSITION;
      problem.message = "position is not finite";
      return err(std::move(problem));
    }
    out.command.position[static_cast<std::size_t>(i)] = p.position[i];
  }
  if (needs_label(out.command.kind)) {
    const std::size_t n = ::strnlen(p.label.chars.data(), p.label.chars.size());
    const std::string_view label(p.label.chars.data(), n);
    const core::LabelProblem check = core::check_label(label);
    if (check != core::LabelProblem::NONE) {
      problem.problem = static_cast<std::uint32_t>(check);
      problem.message = std::string(core::to_string(check));
      return err(std::move(problem));
    }
    out.command.label.assign(label);
  }
  return out;
}

void encode_ack(const RemoteAck& ack, LearningAckPayload& out) noexcept {
  reset_header(out);
  out.status = static_cast<std::uint32_t>(ack.status);
  out.outcome = static_cast<std::uint32_t>(ack.ack.outcome);
  out.client = ack.client;
  out.request = ack.request;
  out.kind = static_cast<std::uint32_t>(ack.ack.kind);
  out.track_id = ack.ack.track_id;
  out.views = ack.ack.views;
  out.unknown = ack.ack.unknown ? 1U : 0U;
  out.frame_id = ack.ack.frame_id;
  out.score = ack.ack.score;
  out.runner_up_score = ack.ack.runner_up_score;
  out.problem = ack.problem;
  out.label = ack.ack.label;
  out.nearest = ack.ack.nearest;
  out.runner_up = ack.ack.runner_up;
}

Result<RemoteAck, std::string> decode_ack(std::span<const std::byte> bytes) {
  LearningAckPayload p;
  std::string error;
  if (!read_whole(bytes, LEARNING_ACK_TYPE_ID, p, error)) return err(std::move(error));
  if (p.status > static_cast<std::uint32_t>(AckStatus::TIMEOUT))
    return err("unknown ack status " + std::to_string(p.status));
  if (p.outcome > static_cast<std::uint32_t>(Outcome::NOTHING_TO_UNDO))
    return err("unknown ack outcome " + std::to_string(p.outcome));
  if (p.kind > static_cast<std::uint32_t>(Kind::UNDO))
    return err("unknown command kind " + std::to_string(p.kind));
  RemoteAck out;
  out.client = p.client;
  out.request = p.request;
  out.status = static_cast<AckStatus>(p.status);
  out.problem = p.problem;
  out.ack.outcome = static_cast<Outcome>(p.outcome);
  out.ack.kind = static_cast<Kind>(p.kind);
  out.ack.track_id = p.track_id;
  out.ack.views = p.views;
  out.ack.unknown = p.unknown != 0;
  out.ack.frame_id = p.frame_id;
  out.ack.score = p.score;
  out.ack.runner_up_score = p.runner_up_score;
  if (!read_text(p.label, out.ack.label) || !read_text(p.nearest, out.ack.nearest) ||
      !read_text(p.runner_up, out.ack.runner_up))
    return err(std::string("a label is not zero-terminated"));
  return out;
}

Result<RemoteStatus, std::string> decode_status(std::span<const std::byte> bytes) {
  // 12.9 KB: copied to the heap, not the stack (the server's worker stacks are small).
  if (bytes.size() < sizeof(StatusPayload))
    return err("payload of " + std::to_string(bytes.size()) + " bytes, expected " +
               std::to_string(sizeof(StatusPayload)));
  auto p = std::make_unique<StatusPayload>();
  std::memcpy(p.get(), bytes.data(), sizeof(StatusPayload));
  if (p->type_id != STATUS_TYPE_ID || p->version != LEARNING_IPC_VERSION ||
      p->payload_bytes != sizeof(StatusPayload))
    return err(std::string("wrong payload type, version or size"));
  if (p->category_count > STATUS_MAX_CATEGORIES || p->node_count > STATUS_MAX_NODES ||
      p->categories_total < p->category_count)
    return err(std::string("category or node count out of range"));
  RemoteStatus out;
  out.durable = p->durable != 0;
  out.frames_done = p->frames_done;
  out.drops = p->drops;
  out.frame_p99_ns = p->frame_p99_ns;
  out.published_ns = p->published_ns;
  out.categories_total = p->categories_total;
  for (std::uint32_t i = 0; i < p->category_count; ++i) {
    StatusCategory c{};
    if (!read_text(p->categories[i].label, c.label) ||
        core::check_label(c.label.view()) != core::LabelProblem::NONE)
      return err("category " + std::to_string(i) + " has a bad label");
    c.views = p->categories[i].views;
    out.categories.push_back(c);
  }
  for (std::uint32_t i = 0; i < p->node_count; ++i) {
    StatusNode n = p->nodes[i];
    if (!read_text(p->nodes[i].name, n.name))
      return err("node " + std::to_string(i) + " has a name that is not zero-terminated");
    out.nodes.push_back(n);
  }
  return out;
}

std::string learning_commands_topic(const std::string& graph) {
  return "orthoflow/" + graph + "/learning_commands";
}
std::string learning_acks_topic(const std::string& graph) {
  return "orthoflow/" + graph + "/learning_acks";
}
std::string status_topic(const std::string& graph) { return "orthoflow/" + graph + "/status"; }

}  // namespace orthoflow::graphs
