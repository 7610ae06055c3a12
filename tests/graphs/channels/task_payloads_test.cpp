// The task command channel's payloads (graphs/channels/task_payloads.hpp): what one process writes,
// another reads back the same; everything another process can get wrong is refused with its reason.
#include <gtest/gtest.h>

#include <cstring>

#include "graphs/channels/task_payloads.hpp"

namespace orthoflow::graphs {
namespace {

template <class P>
std::span<const std::byte> bytes_of(const P& p, std::size_t n = sizeof(P)) {
  return {reinterpret_cast<const std::byte*>(&p), n};
}

TEST(TaskPayloads, ACommandRoundTrips) {
  TaskCommand c;
  c.kind = TaskCommand::Kind::START;
  c.task = manipulation::TableTaskKind::SERVE_A_MEAL;
  c.bring = {"mug", "bowl"};
  TaskCommandPayload p;
  ASSERT_TRUE(encode_task_command(c, 41, 7, p));
  const auto d = decode_task_command(bytes_of(p));
  ASSERT_TRUE(d) << d.error().message;
  EXPECT_EQ(d->client, 41U);
  EXPECT_EQ(d->request, 7U);
  EXPECT_EQ(d->command.kind, TaskCommand::Kind::START);
  EXPECT_EQ(d->command.task, manipulation::TableTaskKind::SERVE_A_MEAL);
  EXPECT_EQ(d->command.bring, (std::vector<std::string>{"mug", "bowl"}));
}

TEST(TaskPayloads, ASenderCannotEncodeWhatTheReaderWouldRefuse) {
  TaskCommand c;
  c.bring = {"a", "b", "c", "d", "e"};
  TaskCommandPayload p;
  EXPECT_FALSE(encode_task_command(c, 1, 1, p));
  c.bring = {"tab\there"};
  EXPECT_FALSE(encode_task_command(c, 1, 1, p));
}

TEST(TaskPayloads, EveryMalformedCommandIsRefusedWithItsReason) {
  TaskCommand c;
  TaskCommandPayload good;
  ASSERT_TRUE(encode_task_command(c, 5, 9, good));
  const auto refused = [](const TaskCommandPayload& p, std::size_t n = sizeof(TaskCommandPayload)) {
    const auto d = decode_task_command(bytes_of(p, n));
    return d ? std::string() : d.error().message;
  };
  EXPECT_NE(refused(good, 100).find("payload of 100 bytes"), std::string::npos);
  TaskCommandPayload p = good;
  p.type_id = 1;
  EXPECT_EQ(refused(p), "wrong payload type or version");
  p = good;
  p.payload_bytes = 12;
  EXPECT_NE(refused(p).find("payload_bytes 12"), std::string::npos);
  p = good;
  p.kind = 2;
  EXPECT_EQ(refused(p), "unknown command kind 2");
  const auto d = decode_task_command(bytes_of(p));
  ASSERT_FALSE(d);
  EXPECT_EQ(d.error().client, 5U);  // whole enough to answer its sender
  EXPECT_EQ(d.error().request, 9U);
  p = good;
  p.task = 9;
  EXPECT_EQ(refused(p), "unknown task 9");
  p = good;
  p.bring_count = 5;
  EXPECT_EQ(refused(p), "bring_count 5 above 4");
  p = good;
  p.bring_count = 1;
  std::memset(p.bring[0].chars.data(), 'x', p.bring[0].chars.size());  // no terminating zero
  EXPECT_EQ(refused(p), "category 0: label is longer than 63 bytes");
  p = good;
  p.bring_count = 1;  // an empty label
  EXPECT_NE(refused(p).find("category 0: "), std::string::npos);
  p = good;
  p.task = static_cast<std::uint32_t>(manipulation::TableTaskKind::SERVE_A_MEAL);
  EXPECT_EQ(refused(p), "serve_a_meal names no category to bring");
}

TEST(TaskPayloads, AStatusRoundTripsAndABadOneIsRefused) {
  TaskStatus s;
  s.state = TaskState::RUNNING;
  s.task = manipulation::TableTaskKind::CLEAR_TABLE;
  s.client = 3;
  s.request = 4;
  s.answer = TaskAnswer::STARTED;
  s.move = 2;
  s.moves = 5;
  s.done = 1;
  s.published_ns = 123;
  s.phase = manipulation::Phase::CARRY;
  s.message = std::string(100, 'm');  // elided to fit
  TaskStatusPayload p;
  encode_task_status(s, p);
  const auto d = decode_task_status(bytes_of(p));
  ASSERT_TRUE(d) << d.error();
  EXPECT_EQ(d->state, TaskState::RUNNING);
  EXPECT_EQ(d->answer, TaskAnswer::STARTED);
  EXPECT_EQ(d->move, 2U);
  EXPECT_EQ(d->moves, 5U);
  EXPECT_EQ(d->done, 1U);
  EXPECT_EQ(d->phase, manipulation::Phase::CARRY);
  EXPECT_EQ(d->message.size(), core::TEXT_MAX_BYTES);
  TaskStatusPayload bad = p;
  bad.phase = 99;
  EXPECT_EQ(decode_task_status(bytes_of(bad)).error(), "phase 99 out of range");
  bad = p;
  bad.done = 3;
  EXPECT_FALSE(decode_task_status(bytes_of(bad)));
  bad = p;
  std::memset(bad.message.chars.data(), 'x', bad.message.chars.size());
  EXPECT_EQ(decode_task_status(bytes_of(bad)).error(), "message is not zero-terminated");
  bad = p;
  bad.answer = 17;
  EXPECT_EQ(decode_task_status(bytes_of(bad)).error(), "answer 17 out of range");
}

TEST(TaskPayloads, TopicsSitBesideTheGraphsLearningChannel) {
  EXPECT_EQ(task_commands_topic("tabletop"), "orthoflow/tabletop/task_commands");
  EXPECT_EQ(task_status_topic("tabletop"), "orthoflow/tabletop/task_status");
}

}  // namespace
}  // namespace orthoflow::graphs
