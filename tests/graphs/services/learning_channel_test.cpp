// The learning channel end to end: a second thread drives a running tabletop session only through
// the channel (teach, ask, correct, forget, undo, each acknowledged) and sees every effect in the
// objects output (graphs/nodes/objects_output.hpp), with the in-memory learner and with a durable
// perceptual memory.
#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <functional>
#include <optional>
#include <string>
#include <thread>

#include "tests/graphs/tabletop_run.hpp"

namespace orthoflow::graphs {
namespace {

using Clock = std::chrono::steady_clock;
using Outcome = LearningAck::Outcome;

/// The person at the table: reads the objects output and talks through one learning client.
class Teacher {
 public:
  Teacher(LearningService& service, ObjectsHub& hub)
      : client_(service.connect()), objects_(hub.subscribe(64)) {}

  /// Waits (at most @p lists object lists, 60 s) for a list in which @p pred holds; returns that
  /// list's frame.
  std::optional<std::uint64_t> wait_for(
      const std::function<bool(const engine::ObjectListPayload&)>& pred, int lists) {
    const auto deadline = Clock::now() + std::chrono::seconds(60);
    for (int seen = 0; seen < lists && Clock::now() < deadline;) {
      if (!objects_->poll(list_)) {
        std::this_thread::sleep_for(std::chrono::milliseconds(1));
        continue;
      }
      ++seen;
      if (pred(list_)) return list_.frame_id;
    }
    return std::nullopt;
  }
  /// Sends @p command and waits (60 s at most) for its acknowledgement.
  std::optional<LearningAck> call(LearningCommand command) {
    const std::uint64_t sequence = client_->send(command);
    if (sequence == 0) return std::nullopt;
    const auto deadline = Clock::now() + std::chrono::seconds(60);
    LearningAck ack;
    while (Clock::now() < deadline) {
      while (client_->poll(ack)) {
        if (ack.sequence == sequence) return ack;
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(1));
    }
    return std::nullopt;
  }
  const engine::ObjectListPayload& last() const { return list_; }

 private:
  std::unique_ptr<LearningClient> client_;
  std::unique_ptr<ObjectsSubscription> objects_;
  engine::ObjectListPayload list_;
};

const engine::ObjectEntry* entry_of(const engine::ObjectListPayload& l, std::uint64_t track) {
  for (std::uint32_t k = 0; k < l.count; ++k) {
    if (l.objects[k].track_id == track && (l.objects[k].flags & engine::OBJECT_FRAGMENT) == 0)
      return &l.objects[k];
  }
  return nullptr;
}

LearningCommand command(LearningCommand::Kind kind, std::uint32_t track, std::string_view label) {
  LearningCommand c;
  c.kind = kind;
  c.track_id = track;
  EXPECT_TRUE(c.label.try_assign(label));
  return c;
}

void teach_correct_forget(LearningService& learning, Outcome stored) {
  ObjectsHub hub;
  SessionLog log(nullptr);
  const auto registry = make_tabletop_registry(learning, log, &hub);
  auto spec =
      test::tabletop_spec({{"source", {{"frames", "900"}}}, {"recognise", {{"instructor", "0"}}}});
  spec.period_ns = 15'000'000;  // paced, so that the teacher acts while the session runs
  auto graph = engine::build_graph(spec, registry);
  ASSERT_TRUE(graph) << engine::to_string(graph.error());
  engine::Engine engine(**graph, {2});
  Teacher teacher(learning, hub);
  std::thread runner([&] { engine.run({}); });
  // A described, still object seen for a few frames: its track has a key view by then.
  std::uint64_t track = 0;
  auto seen = teacher.wait_for(
      [&](const engine::ObjectListPayload& l) {
        for (std::uint32_t k = 0; k < l.count; ++k) {
          const auto& o = l.objects[k];
          if ((o.flags & engine::OBJECT_DESCRIBED) && !(o.flags & engine::OBJECT_MOVING) &&
              l.frame_id >= 5)
            track = o.track_id;
        }
        return track != 0;
      },
      200);
  ASSERT_TRUE(seen);
  EXPECT_TRUE(entry_of(teacher.last(), track)->unknown);  // nothing is known yet
  // a refused teach stores nothing and keeps the key views for the next one
  LearningCommand empty_label =
      command(LearningCommand::Kind::TEACH, static_cast<std::uint32_t>(track), "x");
  empty_label.label = core::Text{};
  auto bad = teacher.call(empty_label);
  ASSERT_TRUE(bad);
  EXPECT_EQ(bad->outcome, Outcome::BAD_LABEL);
  // teach: the key views and the current view are stored
  auto taught = teacher.call(
      command(LearningCommand::Kind::TEACH, static_cast<std::uint32_t>(track), "alpha"));
  ASSERT_TRUE(taught);
  EXPECT_EQ(taught->outcome, stored) << to_string(taught->outcome);
  EXPECT_GE(taught->views, 2U);
  EXPECT_EQ(taught->track_id, track);
  auto labelled = [&](std::string_view label) {
    return [&, label](const engine::ObjectListPayload& l) {
      const auto* o = entry_of(l, track);
      return o != nullptr && (label.empty() ? o->unknown == 1 : o->label.view() == label);
    };
  };
  ASSERT_TRUE(teacher.wait_for(labelled("alpha"), 30))
      << "the taught label never showed in the objects output";
  // ask
  auto asked =
      teacher.call(command(LearningCommand::Kind::ASK, static_cast<std::uint32_t>(track), ""));
  ASSERT_TRUE(asked);
  EXPECT_EQ(asked->outcome, Outcome::ANSWERED);
  EXPECT_EQ(asked->label.view(), "alpha");
  EXPECT_FALSE(asked->unknown);
  // correct, then forget the wrong category: only the correction is left
  auto corrected = teacher.call(
      command(LearningCommand::Kind::CORRECT, static_cast<std::uint32_t>(track), "beta"));
  ASSERT_TRUE(corrected);
  EXPECT_EQ(corrected->outcome, stored);
  EXPECT_EQ(corrected->views, 1U);
  auto forgot = teacher.call(command(LearningCommand::Kind::FORGET, 0, "alpha"));
  ASSERT_TRUE(forgot);
  EXPECT_EQ(forgot->outcome, stored);
  ASSERT_TRUE(teacher.wait_for(labelled("beta"), 30))
      << "the correction never showed in the objects output";
  auto again = teacher.call(command(LearningCommand::Kind::FORGET, 0, "alpha"));
  ASSERT_TRUE(again);
  EXPECT_EQ(again->outcome, Outcome::UNKNOWN_LABEL);
  // undo takes back the correction (its category had nothing else); alpha's teach went with the
  // forget, so there is nothing further to undo
  auto undone = teacher.call(command(LearningCommand::Kind::UNDO, 0, ""));
  ASSERT_TRUE(undone);
  EXPECT_EQ(undone->outcome, stored) << to_string(undone->outcome);
  EXPECT_EQ(undone->label.view(), "beta");
  EXPECT_EQ(undone->views, 1U);
  ASSERT_TRUE(teacher.wait_for(labelled(""), 30))
      << "undoing the only lesson left did not make the object Unknown";
  auto nothing = teacher.call(command(LearningCommand::Kind::UNDO, 0, ""));
  ASSERT_TRUE(nothing);
  EXPECT_EQ(nothing->outcome, Outcome::NOTHING_TO_UNDO);
  // teach twice, undo once: the first lesson stays and still names the object
  ASSERT_EQ(
      teacher
          .call(command(LearningCommand::Kind::TEACH, static_cast<std::uint32_t>(track), "beta"))
          ->outcome,
      stored);
  ASSERT_EQ(
      teacher
          .call(command(LearningCommand::Kind::CORRECT, static_cast<std::uint32_t>(track), "beta"))
          ->outcome,
      stored);
  auto second = teacher.call(command(LearningCommand::Kind::UNDO, 0, ""));
  ASSERT_TRUE(second);
  EXPECT_EQ(second->outcome, stored);
  EXPECT_EQ(second->views, 1U);
  ASSERT_TRUE(teacher.wait_for(labelled("beta"), 30)) << "undo took more than its lesson";
  ASSERT_TRUE(teacher.call(command(LearningCommand::Kind::FORGET, 0, "beta")));
  ASSERT_TRUE(teacher.wait_for(labelled(""), 30))
      << "forgetting every category did not make the object Unknown";
  // errors come back too
  auto missing = teacher.call(command(LearningCommand::Kind::TEACH, 99999, "gamma"));
  ASSERT_TRUE(missing);
  EXPECT_EQ(missing->outcome, Outcome::NO_SUCH_TRACK);
  // by position: a point near the object's centroid teaches it; one farther than
  // TEACH_POSITION_MAX_M from every object teaches nothing (never the nearest neighbour)
  const engine::ObjectEntry* here = entry_of(teacher.last(), track);
  ASSERT_NE(here, nullptr);
  LearningCommand near = command(LearningCommand::Kind::TEACH, 0, "gamma");
  near.by_position = true;
  near.position = {here->centroid[0] + 0.02F, here->centroid[1], here->centroid[2]};
  auto pointed = teacher.call(near);
  ASSERT_TRUE(pointed);
  EXPECT_EQ(pointed->outcome, stored) << to_string(pointed->outcome);
  EXPECT_EQ(pointed->track_id, track);
  LearningCommand far = near;
  far.position = {here->centroid[0], here->centroid[1] - 5.0F, here->centroid[2]};
  auto nowhere = teacher.call(far);
  ASSERT_TRUE(nowhere);
  EXPECT_EQ(nowhere->outcome, Outcome::NO_SUCH_TRACK);
  ASSERT_TRUE(teacher.call(command(LearningCommand::Kind::FORGET, 0, "gamma")));
  engine.request_stop();
  runner.join();
  EXPECT_EQ(learning.commands_dropped(), 0U);
  EXPECT_EQ(learning.acks_dropped(), 0U);
}

TEST(LearningChannel, SecondThreadTeachesCorrectsAndForgetsInMemory) {
  auto learning = test::in_memory_learning();
  teach_correct_forget(*learning, Outcome::LEARNED);
  EXPECT_EQ(learning->learner().stats().categories, 0U);
}

TEST(LearningChannel, SecondThreadTeachesCorrectsAndForgetsDurably) {
  const auto dir =
      std::filesystem::temp_directory_path() / ("orthoflow_channel_" + std::to_string(::getpid()));
  std::filesystem::remove_all(dir);
  LearningSettings settings;
  settings.db = dir;
  auto learning = LearningService::open(settings);
  ASSERT_TRUE(learning) << learning.error();
  teach_correct_forget(**learning, Outcome::STORED);
  (*learning)->flush();
  EXPECT_EQ((*learning)->learner().stats().categories, 0U);
  learning->reset();
  std::filesystem::remove_all(dir);
}

// Lessons of sets of spin images (19,585 floats a view, far past GOOD's room) through the durable
// writer: more lessons than the writer's 16 job slots, so every slot's room is used again; every
// value reaches the store in order, and an undo takes back exactly the last lesson.
TEST(LearningChannel, DurableLessonsOfSpinSetsReachTheStoreValueForValue) {
  const auto dir =
      std::filesystem::temp_directory_path() / ("orthoflow_spin_" + std::to_string(::getpid()));
  std::filesystem::remove_all(dir);
  LearningSettings settings;
  settings.db = dir;
  settings.memory.descriptor = kernels::DescriptorSpec::make_spin_set();
  const std::size_t length = settings.memory.descriptor.length();
  const std::size_t images = kernels::SpinSetParams{}.image_values();
  ASSERT_EQ(length, 19'585U);
  auto learning = LearningService::open(settings);
  ASSERT_TRUE(learning) << learning.error();
  // Lesson l, view v: a set of (l + v) % 5 + 1 images whose values name the lesson and the view.
  auto lesson = [&](std::size_t l) {
    std::vector<float> views(MAX_TEACH_VIEWS * length, 0.0F);
    for (std::size_t v = 0; v < MAX_TEACH_VIEWS; ++v) {
      float* set = views.data() + v * length;
      const std::size_t n = (l + v) % 5 + 1;
      set[0] = static_cast<float>(n);
      for (std::size_t i = 0; i < n * images; ++i)
        set[1 + i] = static_cast<float>(l * 1000 + v * 10 + i % 7 + 1) * 1e-4F;
    }
    return views;
  };
  constexpr std::size_t LESSONS = 20;
  for (std::size_t l = 0; l < LESSONS; ++l) {
    const auto views = lesson(l);
    LearningAck ack = (*learning)->teach(l % 2 == 0 ? "even" : "odd", views, 1, 0, {});
    EXPECT_EQ(ack.outcome, Outcome::STORED) << l;
    EXPECT_EQ(ack.views, MAX_TEACH_VIEWS);
    (*learning)->flush();  // the ring holds 16: wait so that none is refused BUSY
  }
  const LearningAck undone = (*learning)->undo({});
  EXPECT_EQ(undone.outcome, Outcome::STORED);
  EXPECT_EQ(undone.label.view(), "odd");
  (*learning)->flush();
  EXPECT_EQ((*learning)->learner().stats().views, (LESSONS - 1) * MAX_TEACH_VIEWS);
  learning->reset();
  auto memory = learning::PerceptualMemory::open(dir, settings.memory);
  ASSERT_TRUE(memory) << memory.error().to_string();
  for (const auto& entry : memory->list()) {
    auto stored = memory->views_of(entry.id);
    ASSERT_TRUE(stored);
    const std::size_t parity = entry.label == "even" ? 0 : 1;
    const std::size_t lessons = entry.label == "even" ? LESSONS / 2 : LESSONS / 2 - 1;
    ASSERT_EQ(stored->size(), lessons * MAX_TEACH_VIEWS) << entry.label;
    for (std::size_t k = 0; k < lessons; ++k) {
      const auto views = lesson(2 * k + parity);
      for (std::size_t v = 0; v < MAX_TEACH_VIEWS; ++v) {
        const auto& got = (*stored)[k * MAX_TEACH_VIEWS + v].descriptor;
        ASSERT_EQ(got.size(), length);
        EXPECT_TRUE(std::equal(got.begin(), got.end(), views.begin() + v * length))
            << entry.label << " lesson " << k << " view " << v;
      }
    }
  }
  std::filesystem::remove_all(dir);
}

TEST(LearningChannel, ClientsAreBoundedAndSlotsAreReused) {
  auto learning = test::in_memory_learning();
  std::vector<std::unique_ptr<LearningClient>> clients;
  for (std::size_t i = 0; i < MAX_LEARNING_CLIENTS; ++i) clients.push_back(learning->connect());
  for (const auto& c : clients) ASSERT_TRUE(c);
  EXPECT_EQ(learning->connect(), nullptr);
  const std::uint32_t freed = clients[3]->id();
  clients[3].reset();
  auto again = learning->connect();
  ASSERT_TRUE(again);
  EXPECT_EQ(again->id(), freed);
  // a full command queue refuses and counts; nothing blocks
  std::size_t accepted = 0;
  for (int i = 0; i < 100; ++i)
    accepted += again->send(command(LearningCommand::Kind::ASK, 1, "")) != 0 ? 1 : 0;
  EXPECT_EQ(accepted, 64U);
  EXPECT_EQ(learning->commands_dropped(), 36U);
}

}  // namespace
}  // namespace orthoflow::graphs
