#include "bridge/command_relay.hpp"

namespace orthoflow::bridge {

RelayDecision CommandRelay::on_command(const RosLearningCommand& command, std::int64_t now_ns,
                                       bool graph_listening) {
  RelayDecision d;
  d.route = {command.client, command.request};
  d.answer.client = command.client;
  d.answer.request = command.request;
  d.answer.ack.kind = command.kind <= static_cast<std::uint8_t>(graphs::LearningCommand::Kind::UNDO)
                          ? static_cast<graphs::LearningCommand::Kind>(command.kind)
                          : graphs::LearningCommand::Kind::TEACH;
  d.answer.ack.track_id = command.track_id;
  const std::uint64_t request = next_request_ + 1;
  auto payload = from_ros(command, client_, request);
  if (!payload) {
    d.answer.status = graphs::AckStatus::INVALID;
    d.answer.problem = payload.error().problem;
    d.problem = payload.error().message;
    return d;
  }
  if (!graph_listening) {
    d.answer.status = graphs::AckStatus::TIMEOUT;
    d.problem = "no graph is listening for learning commands";
    return d;
  }
  Slot* free = nullptr;
  for (Slot& s : slots_) {
    if (!s.used) {
      free = &s;
      break;
    }
  }
  if (free == nullptr) {
    d.answer.status = graphs::AckStatus::QUEUE_FULL;
    d.problem = "the bridge has 256 commands waiting for the graph: send again later";
    return d;
  }
  next_request_ = request;
  *free = {true, request, d.route, now_ns + timeout_ns_};
  ++pending_;
  d.forward = true;
  d.payload = *payload;
  d.bridge_request = request;
  return d;
}

std::optional<AckRoute> CommandRelay::on_ack(const graphs::RemoteAck& ack) noexcept {
  if (ack.client != client_) return std::nullopt;
  for (Slot& s : slots_) {
    if (s.used && s.bridge_request == ack.request) {
      s.used = false;
      --pending_;
      return s.route;
    }
  }
  return std::nullopt;  // answered already (timed out here), or a stray
}

void CommandRelay::cancel(std::uint64_t bridge_request) noexcept {
  for (Slot& s : slots_) {
    if (s.used && s.bridge_request == bridge_request) {
      s.used = false;
      --pending_;
      return;
    }
  }
}

std::optional<AckRoute> CommandRelay::next_expired(std::int64_t now_ns) noexcept {
  if (pending_ == 0) return std::nullopt;
  for (Slot& s : slots_) {
    if (s.used && now_ns > s.deadline_ns) {
      s.used = false;
      --pending_;
      return s.route;
    }
  }
  return std::nullopt;
}

}  // namespace orthoflow::bridge
