// Fuzzes the learning channel's payload decoding (graphs/channels/learning_payloads.hpp): what
// another process publishes as a command, an acknowledgement or a status. The first byte picks the
// payload and whether its header is made right (so the fuzzer reaches the fields behind it); the
// rest fills the payload. No input may crash, hang, leak or hit UB; a decoded command must hold a
// known kind and, where its kind needs one, a label the label rule accepts, and re-encode to
// itself; a decoded ack or status must hold only what its ranges allow.
#include <cmath>
#include <cstdint>
#include <cstring>
#include <memory>
#include <span>

#include "core/label_text.hpp"
#include "graphs/channels/learning_payloads.hpp"
#include "tests/fuzz/fuzz_payload_support.hpp"

namespace g = orthoflow::graphs;

namespace {

using Kind = g::LearningCommand::Kind;

using orthoflow::fuzz::bytes_of;
using orthoflow::fuzz::filled;

void check_command(const std::uint8_t* data, std::size_t size, bool fix, bool whole) {
  const auto p = filled<g::LearningCommandPayload>(data, size, fix);
  const auto d = g::decode_command(bytes_of(*p, whole ? sizeof *p : size));
  if (!d) {
    if (d.error().message.empty()) __builtin_trap();
    return;
  }
  const g::LearningCommand& c = d->command;
  if (static_cast<std::uint32_t>(c.kind) > static_cast<std::uint32_t>(Kind::UNDO)) __builtin_trap();
  const bool labelled = c.kind == Kind::TEACH || c.kind == Kind::CORRECT || c.kind == Kind::FORGET;
  if (labelled &&
      orthoflow::core::check_label(c.label.view()) != orthoflow::core::LabelProblem::NONE)
    __builtin_trap();
  if (c.by_position && !(std::isfinite(c.position[0]) && std::isfinite(c.position[1]) &&
                         std::isfinite(c.position[2])))
    __builtin_trap();
  g::LearningCommandPayload again;
  if (!g::encode_command(c, d->client, d->request, again)) __builtin_trap();
  const auto twice = g::decode_command(bytes_of(again, sizeof again));
  if (!twice || twice->command.kind != c.kind || twice->command.label.view() != c.label.view() ||
      twice->client != d->client || twice->request != d->request)
    __builtin_trap();
}

void check_ack(const std::uint8_t* data, std::size_t size, bool fix, bool whole) {
  const auto p = filled<g::LearningAckPayload>(data, size, fix);
  const auto d = g::decode_ack(bytes_of(*p, whole ? sizeof *p : size));
  if (!d) return;
  if (static_cast<std::uint32_t>(d->status) > static_cast<std::uint32_t>(g::AckStatus::TIMEOUT) ||
      d->ack.label.view().size() > orthoflow::core::TEXT_MAX_BYTES ||
      d->ack.nearest.view().size() > orthoflow::core::TEXT_MAX_BYTES)
    __builtin_trap();
}

void check_status(const std::uint8_t* data, std::size_t size, bool fix, bool whole) {
  const auto p = filled<g::StatusPayload>(data, size, fix);
  const auto d = g::decode_status(bytes_of(*p, whole ? sizeof *p : size));
  if (!d) return;
  if (d->categories.size() > g::STATUS_MAX_CATEGORIES || d->nodes.size() > g::STATUS_MAX_NODES)
    __builtin_trap();
  for (const g::StatusCategory& c : d->categories)
    if (orthoflow::core::check_label(c.label.view()) != orthoflow::core::LabelProblem::NONE)
      __builtin_trap();
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size == 0) return 0;
  const std::uint8_t pick = data[0];
  const bool fix = (pick & 0x10U) != 0, whole = (pick & 0x20U) != 0;
  switch (pick % 3U) {
    case 0:
      check_command(data + 1, size - 1, fix, whole);
      break;
    case 1:
      check_ack(data + 1, size - 1, fix, whole);
      break;
    default:
      check_status(data + 1, size - 1, fix, whole);
      break;
  }
  return 0;
}
