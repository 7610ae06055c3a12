// Fuzzes the task command channel's payload decoding (graphs/channels/task_payloads.hpp): what
// another process publishes as a task command or a task status. The first byte picks the payload
// and whether its header is made right (so the fuzzer reaches the fields behind it); the rest fills
// the payload. No input may crash, hang, leak or hit UB; a decoded command must hold a known kind
// and task, at most TASK_MAX_BRING categories the label rule accepts, and re-encode to itself; a
// decoded status must hold only what its ranges allow.
#include <cstdint>
#include <cstring>
#include <memory>
#include <span>

#include "core/label_text.hpp"
#include "graphs/channels/task_payloads.hpp"
#include "tests/fuzz/fuzz_payload_support.hpp"

namespace g = orthoflow::graphs;

namespace {

using orthoflow::fuzz::bytes_of;
using orthoflow::fuzz::filled;

void check_command(const std::uint8_t* data, std::size_t size, bool fix, bool whole) {
  const auto p = filled<g::TaskCommandPayload>(data, size, fix);
  const auto d = g::decode_task_command(bytes_of(*p, whole ? sizeof *p : size));
  if (!d) {
    if (d.error().message.empty()) __builtin_trap();
    return;
  }
  const g::TaskCommand& c = d->command;
  if (static_cast<std::uint32_t>(c.kind) > static_cast<std::uint32_t>(g::TaskCommand::Kind::STOP) ||
      static_cast<std::uint32_t>(c.task) > 1U || c.bring.size() > g::TASK_MAX_BRING)
    __builtin_trap();
  for (const std::string& b : c.bring)
    if (orthoflow::core::check_label(b) != orthoflow::core::LabelProblem::NONE) __builtin_trap();
  g::TaskCommandPayload again;
  if (!g::encode_task_command(c, d->client, d->request, again)) __builtin_trap();
  const auto twice = g::decode_task_command(bytes_of(again, sizeof again));
  if (!twice || twice->command.kind != c.kind || twice->command.task != c.task ||
      twice->command.bring != c.bring || twice->client != d->client || twice->request != d->request)
    __builtin_trap();
}

void check_status(const std::uint8_t* data, std::size_t size, bool fix, bool whole) {
  const auto p = filled<g::TaskStatusPayload>(data, size, fix);
  const auto d = g::decode_task_status(bytes_of(*p, whole ? sizeof *p : size));
  if (!d) return;
  if (static_cast<std::uint32_t>(d->state) > static_cast<std::uint32_t>(g::TaskState::FINISHED) ||
      static_cast<std::uint32_t>(d->answer) > static_cast<std::uint32_t>(g::TaskAnswer::INVALID) ||
      d->move > d->moves || d->done > d->move ||
      d->message.size() > orthoflow::core::TEXT_MAX_BYTES)
    __builtin_trap();
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size == 0) return 0;
  const std::uint8_t pick = data[0];
  const bool fix = (pick & 0x10U) != 0, whole = (pick & 0x20U) != 0;
  if (pick % 2U == 0)
    check_command(data + 1, size - 1, fix, whole);
  else
    check_status(data + 1, size - 1, fix, whole);
  return 0;
}
