// Proves that the tabletop graph, after warm-up, performs no operator new per frame: sources,
// segmentation, tracking, GOOD, recognition (asking a learner that knows categories) and the
// session log, the objects output with an in-process consumer that asks over the learning channel.
// Teaching is excluded: a teach rebuilds the learner's snapshot (it allocates, once per lesson, by
// design; docs/TABLETOP.md). oneTBB's own task allocations do not go through operator new (see
// tests/engine/engine_alloc_test.cpp).
#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <cstdlib>
#include <new>
#include <thread>
#include <vector>

#include <unistd.h>

#include "core/rng.hpp"
#include "drivers/jaco/jaco_kinematics.hpp"
#include "formats/pcd_io.hpp"
#include "graphs/nodes/body_filter_node.hpp"
#include "graphs/nodes/descriptor_params.hpp"
#include "graphs/nodes/labels_writer.hpp"
#include "kernels/frame_labels.hpp"
#include "learning/dictionary.hpp"
#include "learning/topic_training.hpp"
#include "tabletop_run.hpp"

#include "tests/support/counting_new.hpp"  // the one TU of this binary that replaces operator new

using orthoflow::test::g_allocations;
using orthoflow::test::g_counted_thread;
using orthoflow::test::g_counting;

namespace orthoflow::graphs {
namespace {

/// Starts counting allocations once the graph has logged 20 frames (the warm-up), or at @p stop.
std::thread count_after_warm_up(SessionLog& log, const std::atomic<bool>& stop) {
  return std::thread([&log, &stop] {
    while (log.summary().frames < 20 && !stop.load())
      std::this_thread::sleep_for(std::chrono::milliseconds(1));
    g_counting.store(true);
  });
}

TEST(TabletopAllocations, SteadyStateAllocatesNothingPerFrame) {
  auto learning = test::in_memory_learning();
  // A learner that knows categories, so every ask walks real stored views.
  std::vector<float> views(3 * 675, 0.0F);
  for (std::size_t i = 0; i < views.size(); ++i) views[i] = static_cast<float>(i % 7) / 675.0F;
  ASSERT_TRUE(
      learning->teach("thing", std::span<const float>(views).first(2 * 675), 0, 0, {}).ok());
  ASSERT_TRUE(learning->teach("other", std::span<const float>(views).last(675), 0, 0, {}).ok());
  // a JSON sink too: its writer thread writes to /dev/null
  auto json = LineWriter::open("/dev/null");
  ASSERT_TRUE(json);
  SessionLog log(std::move(*json));
  ObjectsHub hub;  // an in-process consumer of the objects output, asking over the learning channel
  auto objects = hub.subscribe(16);
  // A viewer of the camera image (the web view) asking for every frame: the tap copies each one.
  const auto now_ns = [] { return std::chrono::steady_clock::now().time_since_epoch().count(); };
  hub.camera().request(now_ns(), 0, 600'000'000'000);
  auto client = learning->connect();
  const auto registry = make_tabletop_registry(*learning, log, &hub);
  // random scene with 5 objects, instructor off (teaching allocates by design)
  auto spec = test::tabletop_spec(
      {{"source", {{"objects", "5"}, {"frames", "60"}}}, {"recognise", {{"instructor", "0"}}}});
  auto graph = engine::build_graph(spec, registry);
  ASSERT_TRUE(graph) << engine::to_string(graph.error());
  engine::Engine engine(**graph, {2});
  // warm-up: 20 frames, then count over the remaining 40
  std::atomic<bool> stop{false};
  std::thread arm = count_after_warm_up(log, stop);
  std::uint64_t lists = 0, answers = 0, judged = 0;
  std::thread consumer([&] {
    engine::ObjectListPayload list;
    LearningAck ack;
    while (!stop.load()) {
      while (objects->poll(list)) {
        ++lists;
        // The table verdict travels with the objects: accepted (1), up from the sensor (2).
        judged += list.table_reason == 1 && list.gravity == 2 ? 1U : 0U;
        if (list.count > 0) {
          LearningCommand ask;
          ask.kind = LearningCommand::Kind::ASK;
          ask.track_id = static_cast<std::uint32_t>(list.objects[0].track_id);
          (void)client->send(ask);
        }
      }
      while (client->poll(ack)) answers += ack.outcome == LearningAck::Outcome::ANSWERED ? 1 : 0;
      std::this_thread::sleep_for(std::chrono::milliseconds(1));
    }
  });
  engine.run({});
  g_counting.store(false);
  stop.store(true);
  arm.join();
  consumer.join();
  EXPECT_GT(lists, 40U);
  EXPECT_EQ(judged, lists);
  EXPECT_GT(answers, 20U);
  EXPECT_EQ(log.summary().frames, 60U);
  EXPECT_GT(log.summary().object_views, 100U);
  EXPECT_GT(log.summary().recognitions, 100U);
  EXPECT_EQ(g_allocations.load(), 0U);
  EXPECT_GE(hub.camera().copied() + hub.camera().busy(), 60U);
  CameraImage image;
  ASSERT_TRUE(hub.camera().take(image, 0));
  EXPECT_GT(image.frame_id, 40U);  // one of the last frames
  EXPECT_EQ(image.step, 2U);
  EXPECT_EQ(image.width * image.height, image.z.size());
}

TEST(TabletopAllocations, KinectSourceSteadyStateAllocatesNothingPerFrame) {
  // The graph fed by the Kinect driver (kinect_source on the simulated camera, paced to the wall
  // clock): the USB thread (packets, assembly, unpack, publication) and the graph's threads.
  auto learning = test::in_memory_learning();
  auto json = LineWriter::open("/dev/null");
  ASSERT_TRUE(json);
  SessionLog log(std::move(*json));
  const auto registry = make_tabletop_registry(*learning, log, nullptr);
  auto spec = test::tabletop_spec(
      {{"source", {{"kind", "kinect_source"}, {"device", "sim"}, {"wait_ms", "3000"}}},
       {"recognise", {{"instructor", "0"}}}});
  auto graph = engine::build_graph(spec, registry);
  ASSERT_TRUE(graph) << engine::to_string(graph.error());
  engine::Engine engine(**graph, {2});
  std::atomic<bool> stop{false};
  std::thread arm([&] {
    while (log.summary().frames < 15 && !stop.load())
      std::this_thread::sleep_for(std::chrono::milliseconds(1));
    g_counting.store(true);
  });
  engine.run({45, nullptr});  // 1.5 s of camera time; counted over the last 30 frames
  g_counting.store(false);
  stop.store(true);
  arm.join();
  EXPECT_EQ(log.summary().frames, 45U);
  EXPECT_EQ(log.summary().frames_with_table, 45U);
  EXPECT_EQ(g_allocations.load(), 0U);
}

TEST(TabletopAllocations, WithTheRobotBodyFilterNothingIsAllocatedPerFrame) {
  // The graph with body_filter in front of preprocess, fed by an arm in this process writing its
  // state at 500 Hz: looking the arm up, its capsules and the mask allocate nothing.
  auto learning = test::in_memory_learning();
  auto json = LineWriter::open("/dev/null");
  ASSERT_TRUE(json);
  SessionLog log(std::move(*json));
  ArmStateChannel channel;
  const auto registry = make_tabletop_registry(*learning, log, nullptr, nullptr, &channel);
  auto spec = test::tabletop_spec(
      {{"source", {{"objects", "5"}, {"frames", "60"}}}, {"recognise", {{"instructor", "0"}}}});
  engine::ParamMap body;
  body.assign("robot_frames", ORTHOFLOW_SOURCE_DIR "/config/robot_frames_synthetic.yaml");
  body.assign("state", "channel");
  body.assign("max_state_age_ms", "1000");  // under a sanitizer a frame may wait long in a queue
  ASSERT_TRUE(insert_body_filter(spec, body));
  auto graph = engine::build_graph(spec, registry);
  ASSERT_TRUE(graph) << engine::to_string(graph.error());
  engine::Engine engine(**graph, {2});
  std::atomic<bool> stop{false};
  std::thread arm([&] {
    engine::ArmStatePayload state;
    state.reset();
    for (std::size_t j = 0; j < 6; ++j) state.joints_deg[j] = drivers::jaco::HOME_JOINTS[j];
    bool counting = false;  // summary() copies strings: not called once counting
    while (!stop.load()) {
      state.stamp_ns = std::chrono::steady_clock::now().time_since_epoch().count();
      channel.write(state);
      if (!counting && log.summary().frames >= 20) g_counting.store(counting = true);
      std::this_thread::sleep_for(std::chrono::milliseconds(2));
    }
  });
  while (channel.received() == 0) std::this_thread::sleep_for(std::chrono::milliseconds(1));
  engine.run({});
  g_counting.store(false);
  stop.store(true);
  arm.join();
  EXPECT_EQ(log.summary().frames, 60U);
  EXPECT_EQ(log.summary().frames_with_table, 60U) << "every frame filtered, none dropped";
  EXPECT_EQ(g_allocations.load(), 0U);
}

// Runs @p spec (60 frames of 5 objects) with @p learning and counts allocations after warm-up.
void expect_frames_allocate_nothing(const engine::GraphSpec& spec, LearningService& learning,
                                    const char* described) {
  auto json = LineWriter::open("/dev/null");
  ASSERT_TRUE(json);
  SessionLog log(std::move(*json));
  const auto registry = make_tabletop_registry(learning, log);
  auto graph = engine::build_graph(spec, registry);
  ASSERT_TRUE(graph) << engine::to_string(graph.error());
  engine::Engine engine(**graph, {2});
  std::atomic<bool> stop{false};
  std::thread arm = count_after_warm_up(log, stop);
  engine.run({});
  g_counting.store(false);
  stop.store(true);
  arm.join();
  EXPECT_EQ(log.summary().frames, 60U);
  EXPECT_GT(log.summary().object_views, 100U);
  EXPECT_GT(log.summary().recognitions, 100U)
      << "the objects were described and asked " << described;
  EXPECT_EQ(g_allocations.load(), 0U);
}

// The same graph describing objects by the bag of words (describe: descriptor bow, a dictionary
// file): the spin-feature scratch of the describe node's pool is reserved once, so keypoints,
// normals, spin images and words allocate nothing per frame either; the learner asks in words.
// The describe node over a dictionary (bow: the bag of words; lda: its topics, sampled per object;
// local-lda: word counts, asked in every category's topics): 60 frames of 5 objects, counted after
// warm-up.
void expect_no_allocation_over_words(const std::string& kind) {
  core::Rng rng(4);
  std::vector<float> pool(2000 * 45);
  for (float& v : pool) v = static_cast<float>(rng.uniform() * rng.uniform() * 0.2);
  learning::KMeansParams km;
  km.k = 20;
  auto words = learning::build_dictionary(pool, {}, km, "alloc test");
  ASSERT_TRUE(words) << words.error();
  const std::size_t length = kind == "lda" ? 5 : 20;  // topics, or words
  if (kind == "lda") {
    std::vector<std::vector<float>> views(20);
    for (std::size_t v = 0; v < views.size(); ++v)
      views[v].assign(pool.begin() + static_cast<std::ptrdiff_t>(v * 100 * 45),
                      pool.begin() + static_cast<std::ptrdiff_t>((v + 1) * 100 * 45));
    learning::TopicFitParams tp;
    tp.topics = length;
    ASSERT_TRUE(learning::add_topics(*words, views, tp));
  }
  const std::string file = std::string(ORTHOFLOW_BINARY_DIR) + "/tabletop_alloc_test_words.ofwd";
  ASSERT_EQ(learning::save_dictionary(*words, file), "");
  auto spec = test::tabletop_spec({{"source", {{"objects", "5"}, {"frames", "60"}}},
                                   {"recognise", {{"instructor", "0"}}},
                                   {"describe", {{"descriptor", kind}, {"dictionary", file}}}});
  auto descriptor = descriptor_of_graph(spec);
  ASSERT_TRUE(descriptor) << descriptor.error();
  ASSERT_EQ(descriptor->length(), length);
  LearningSettings settings;
  settings.memory.descriptor = *descriptor;
  auto learning = LearningService::open(settings);
  ASSERT_TRUE(learning) << learning.error();
  // Shares (bag of words, topics) or word counts (Local LDA).
  std::vector<float> views(2 * length,
                           kind == "local-lda" ? 2.0F : 1.0F / static_cast<float>(length));
  ASSERT_TRUE(
      (*learning)->teach("thing", std::span<const float>(views).first(length), 0, 0, {}).ok());
  ASSERT_TRUE(
      (*learning)->teach("other", std::span<const float>(views).last(length), 0, 0, {}).ok());
  expect_frames_allocate_nothing(spec, **learning, "in words");
}

TEST(TabletopAllocations, WithTheBagOfWordsNothingIsAllocatedPerFrame) {
  expect_no_allocation_over_words("bow");
}

TEST(TabletopAllocations, WithLdaTopicsNothingIsAllocatedPerFrame) {
  expect_no_allocation_over_words("lda");
}

TEST(TabletopAllocations, WithLocalLdaNothingIsAllocatedPerFrame) {
  expect_no_allocation_over_words("local-lda");
}

// Every object described by its set of spin images (the thesis's sets, up to 128 images: 19,585
// floats, in a frame block grown for them) and asked by the set learner: nothing allocated per
// frame either.
TEST(TabletopAllocations, WithSetsOfSpinImagesNothingIsAllocatedPerFrame) {
  auto spec = test::tabletop_spec({{"source", {{"objects", "5"}, {"frames", "60"}}},
                                   {"recognise", {{"instructor", "0"}}},
                                   {"describe", {{"descriptor", "spin"}}}});
  fit_pool_to_descriptors(spec);
  auto descriptor = descriptor_of_graph(spec);
  ASSERT_TRUE(descriptor) << descriptor.error();
  ASSERT_EQ(descriptor->kind, kernels::DescriptorKind::SPIN_SET);
  const std::size_t length = descriptor->length();
  const std::size_t images = descriptor->spin_set.image_values();
  LearningSettings settings;
  settings.memory.descriptor = *descriptor;
  auto learning = LearningService::open(settings);
  ASSERT_TRUE(learning) << learning.error();
  for (const char* label : {"thing", "other"}) {  // sets of 3 images each
    std::vector<float> set(length, 0.0F);
    set[0] = 3.0F;
    for (std::size_t i = 0; i < 3 * images; ++i)
      set[1 + i] = static_cast<float>((i + label[0]) % 9) / 64.0F;
    ASSERT_TRUE((*learning)->teach(label, set, 0, 0, {}).ok());
  }
  expect_frames_allocate_nothing(spec, **learning, "as sets");
}

TEST(LabelsWriterAllocations, OfferingAFrameAllocatesNothing) {
  // --labels-out on the frame path: copying a frame into a writer cloud and labelling it allocates
  // nothing (the writer thread's encoding does, off the frame path, and is not counted here).
  const std::uint32_t w = 64, h = 48;
  std::vector<float> x(w * h), y(w * h), z(w * h, 1.0F);
  std::vector<std::int32_t> cluster_of(w * h, -1);
  for (std::size_t i = 0; i < x.size(); ++i) {
    x[i] = float(i % w) * 0.002F, y[i] = float(i / w) * 0.002F;
    if (i % w < 10) cluster_of[i] = 0;
  }
  const std::vector<std::int32_t> slot_of{0};
  const auto dir =
      std::filesystem::temp_directory_path() / ("orthoflow_labels_" + std::to_string(::getpid()));
  {
    auto writer = LabelsWriter::open(dir, w * h, 2);
    ASSERT_TRUE(writer) << writer.error();
    const kernels::CloudView cloud{{x, y, z}, w, h};
    const kernels::Plane plane{{0.0F, 0.0F, -1.0F}, 1.0F};
    ASSERT_TRUE((*writer)->offer(0, cloud, plane, 0.02F, {}, cluster_of, slot_of));  // warm-up
    (*writer)->flush();
    g_counted_thread.store(std::this_thread::get_id());
    g_allocations = 0;
    g_counting = true;
    const bool a = (*writer)->offer(1, cloud, plane, 0.02F, {}, cluster_of, slot_of);
    (*writer)->offer(2, cloud, plane, 0.02F, {}, {}, {});  // no table: all 0 (may be dropped)
    g_counting = false;
    g_counted_thread.store(std::thread::id{});
    EXPECT_TRUE(a);
    EXPECT_EQ(g_allocations.load(), 0U);
    // An unorganized frame has no per-point labels: dropped, counted.
    EXPECT_FALSE((*writer)->offer(3, kernels::CloudView{{x, y, z}, w * h, 1}, plane, 0.02F, {},
                                  cluster_of, slot_of));
    (*writer)->flush();
    EXPECT_GE((*writer)->written(), 2U);
    EXPECT_GE((*writer)->dropped(), 1U);
    EXPECT_TRUE((*writer)->first_error().empty()) << (*writer)->first_error();
  }
  auto back = formats::read_pcd(dir / "frame_000001.pcd");
  ASSERT_TRUE(back) << back.error().to_string();
  ASSERT_EQ(back->width(), w);
  ASSERT_EQ(back->height(), h);
  std::size_t objects = 0, table = 0;
  for (const std::uint32_t l : back->label()) {
    objects += l == kernels::FIRST_OBJECT_LABEL ? 1U : 0U;
    table += l == kernels::TABLE_LABEL ? 1U : 0U;
  }
  EXPECT_EQ(objects, std::size_t{10} * h);
  EXPECT_EQ(table, std::size_t{w - 10} * h);
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace orthoflow::graphs
