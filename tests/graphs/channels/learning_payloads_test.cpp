// The learning channel's payloads across processes (graphs/channels/learning_payloads.hpp): what
// one side encodes the other decodes unchanged, and every field another process could get wrong is
// refused with a reason, never passed on.
#include "graphs/channels/learning_payloads.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <limits>
#include <memory>
#include <span>

#include "core/label_text.hpp"

namespace orthoflow::graphs {
namespace {

using Kind = LearningCommand::Kind;

template <class T>
std::span<const std::byte> bytes_of(const T& value) {
  return {reinterpret_cast<const std::byte*>(&value), sizeof value};
}

LearningCommandPayload teach_payload(std::string_view label) {
  LearningCommand c;
  c.kind = Kind::TEACH;
  c.track_id = 7;
  c.label.assign(label);
  LearningCommandPayload p;
  EXPECT_TRUE(encode_command(c, 0xABCDEF, 3, p));
  return p;
}

TEST(LearningPayloads, ACommandRoundTripsWithItsSendersIds) {
  const LearningCommandPayload p = teach_payload("mug");
  const auto decoded = decode_command(bytes_of(p));
  ASSERT_TRUE(decoded) << decoded.error().message;
  EXPECT_EQ(decoded->client, 0xABCDEFU);
  EXPECT_EQ(decoded->request, 3U);
  EXPECT_EQ(decoded->command.kind, Kind::TEACH);
  EXPECT_EQ(decoded->command.track_id, 7U);
  EXPECT_EQ(decoded->command.label.view(), "mug");
  EXPECT_FALSE(decoded->command.by_position);
}

TEST(LearningPayloads, TheSenderRefusesToEncodeALabelTheRuleRefuses) {
  LearningCommand c;
  c.kind = Kind::FORGET;
  LearningCommandPayload p;
  EXPECT_FALSE(encode_command(c, 1, 1, p));  // empty
  c.label.assign("a\tb");
  EXPECT_FALSE(encode_command(c, 1, 1, p));
  c.kind = Kind::UNDO;  // needs no label
  EXPECT_TRUE(encode_command(c, 1, 1, p));
}

TEST(LearningPayloads, AMalformedCommandIsRefusedNamingItsSender) {
  LearningCommandPayload p = teach_payload("mug");
  p.kind = 9;
  auto d = decode_command(bytes_of(p));
  ASSERT_FALSE(d);
  EXPECT_EQ(d.error().client, 0xABCDEFU);
  EXPECT_EQ(d.error().request, 3U);
  EXPECT_NE(d.error().message.find("kind"), std::string::npos);

  p = teach_payload("mug");
  p.label.chars[0] = static_cast<char>(0xC0);  // an overlong form: not UTF-8
  d = decode_command(bytes_of(p));
  ASSERT_FALSE(d);
  EXPECT_EQ(d.error().problem, static_cast<std::uint32_t>(core::LabelProblem::NOT_UTF8));

  p = teach_payload("mug");
  std::memset(p.label.chars.data(), 'x', p.label.chars.size());  // 64 bytes, no terminator
  d = decode_command(bytes_of(p));
  ASSERT_FALSE(d);
  EXPECT_EQ(d.error().problem, static_cast<std::uint32_t>(core::LabelProblem::TOO_LONG));

  p = teach_payload("mug");
  p.by_position = 1;
  p.position[1] = std::numeric_limits<float>::quiet_NaN();
  EXPECT_FALSE(decode_command(bytes_of(p)));

  p = teach_payload("mug");
  p.payload_bytes = 64;
  EXPECT_FALSE(decode_command(bytes_of(p)));
  p = teach_payload("mug");
  p.version = 2;
  EXPECT_FALSE(decode_command(bytes_of(p)));
  p = teach_payload("mug");
  EXPECT_FALSE(decode_command(bytes_of(p).first(sizeof p - 1)));
  EXPECT_FALSE(decode_command({}));
}

TEST(LearningPayloads, AnAckRoundTripsAndABadOneIsRefused) {
  RemoteAck a;
  a.client = 5;
  a.request = 6;
  a.status = AckStatus::ACKNOWLEDGED;
  a.ack.kind = Kind::ASK;
  a.ack.outcome = LearningAck::Outcome::ANSWERED;
  a.ack.track_id = 2;
  a.ack.unknown = false;
  a.ack.score = 0.25F;
  a.ack.label.assign("bowl");
  a.ack.nearest.assign("bowl");
  a.ack.runner_up.assign("mug");
  a.ack.runner_up_score = 0.5F;
  a.ack.frame_id = 99;
  LearningAckPayload p;
  encode_ack(a, p);
  const auto d = decode_ack(bytes_of(p));
  ASSERT_TRUE(d) << d.error();
  EXPECT_EQ(d->client, 5U);
  EXPECT_EQ(d->request, 6U);
  EXPECT_EQ(d->status, AckStatus::ACKNOWLEDGED);
  EXPECT_EQ(d->ack.outcome, LearningAck::Outcome::ANSWERED);
  EXPECT_EQ(d->ack.label.view(), "bowl");
  EXPECT_EQ(d->ack.runner_up.view(), "mug");
  EXPECT_FLOAT_EQ(d->ack.runner_up_score, 0.5F);
  EXPECT_EQ(d->ack.frame_id, 99U);
  EXPECT_FALSE(d->ack.unknown);

  LearningAckPayload bad = p;
  bad.outcome = 200;
  EXPECT_FALSE(decode_ack(bytes_of(bad)));
  bad = p;
  bad.status = 9;
  EXPECT_FALSE(decode_ack(bytes_of(bad)));
  bad = p;
  std::memset(bad.nearest.chars.data(), 'y', bad.nearest.chars.size());
  EXPECT_FALSE(decode_ack(bytes_of(bad)));
}

TEST(LearningPayloads, AStatusRoundTripsAndCountsBeyondItsCapacityAreRefused) {
  auto p = std::make_unique<StatusPayload>();
  reset_header(*p);
  p->durable = 1;
  p->category_count = 2;
  p->categories_total = 2;
  p->categories[0] = {core::Text::from("mug"), 4};
  p->categories[1] = {core::Text::from("bowl"), 2};
  p->node_count = 1;
  p->nodes[0] = {core::Text::from("describe"), 10, 1, 0, 100, 200, 300};
  p->frames_done = 10;
  auto d = decode_status(bytes_of(*p));
  ASSERT_TRUE(d) << d.error();
  EXPECT_TRUE(d->durable);
  ASSERT_EQ(d->categories.size(), 2U);
  EXPECT_EQ(d->categories[1].label.view(), "bowl");
  EXPECT_EQ(d->categories[1].views, 2U);
  ASSERT_EQ(d->nodes.size(), 1U);
  EXPECT_EQ(d->nodes[0].name.view(), "describe");
  EXPECT_EQ(d->nodes[0].p99_ns, 200);

  p->category_count = STATUS_MAX_CATEGORIES + 1;
  EXPECT_FALSE(decode_status(bytes_of(*p)));
  p->category_count = 2;
  p->categories[0].label.chars[0] = '\n';  // a label the rule refuses
  EXPECT_FALSE(decode_status(bytes_of(*p)));
  p->categories[0].label.assign("mug");
  p->node_count = STATUS_MAX_NODES + 1;
  EXPECT_FALSE(decode_status(bytes_of(*p)));
  EXPECT_FALSE(decode_status(bytes_of(*p).first(100)));
}

}  // namespace
}  // namespace orthoflow::graphs
