// The DDS bridge's cost per message (issue 23): an object list and a 640 x 480 frame turned into
// their ROS 2 messages (bridge/ros_messages.hpp), and the frame's PointCloud2 written through
// Cyclone DDS (serialisation included) to a reader in the same process on a loopback domain.
#include <benchmark/benchmark.h>

#include <cmath>
#include <cstring>
#include <memory>
#include <vector>

#include <dds/dds.h>

#include "bridge/bridge_config.hpp"
#include "bridge/ros_messages.hpp"

namespace {

namespace b = orthoflow::bridge;
namespace engine = orthoflow::engine;

std::unique_ptr<engine::ObjectListPayload> full_list() {
  auto list = std::make_unique<engine::ObjectListPayload>();
  std::memset(static_cast<void*>(list.get()), 0, sizeof *list);
  list->reset_header();
  list->count = engine::OBJECT_LIST_CAPACITY;
  for (auto& e : list->objects) {
    e.track_id = 3;
    e.label.assign("bottle");
    for (int r = 0; r < 4; ++r)
      for (int c = 0; c < 4; ++c) e.frame[4 * r + c] = r == c ? 1.0F : 0.0F;
    e.frame[11] = -1.0F;
    e.bbox[0] = e.bbox[1] = 0.07F;
    e.bbox[2] = 0.2F;
    e.flags = engine::OBJECT_DESCRIBED;
  }
  return list;
}

struct Frame {
  std::vector<std::byte> storage;
  engine::FrameView view;
  Frame() {
    constexpr std::uint32_t W = 640, H = 480;
    storage.resize(engine::frame_payload_bytes(W, H, engine::FRAME_FIELD_RGB) + 64);
    auto* aligned = reinterpret_cast<std::byte*>(
        (reinterpret_cast<std::uintptr_t>(storage.data()) + 63) & ~std::uintptr_t{63});
    auto span = engine::layout_frame({aligned, storage.size() - 64}, W, H, engine::FRAME_FIELD_RGB);
    for (std::size_t i = 0; i < W * H; ++i) {
      span->points.x[i] = 0.001F * static_cast<float>(i % W);
      span->points.y[i] = 0.001F * static_cast<float>(i / W);
      span->points.z[i] = i % 17 == 0 ? std::nanf("") : 1.0F;
      span->rgb[i] = 0xFF808080U;
    }
    view = *engine::view_frame({aligned, span->header->payload_bytes});
  }
};

void BM_ObjectListToRos(benchmark::State& state) {
  const auto list = full_list();
  b::RosScratch scratch;
  b::RosObjectArray msg{};
  const b::StampClock clock;
  for (auto _ : state) benchmark::DoNotOptimize(b::to_ros(*list, clock, scratch, msg));
  state.counters["objects"] = static_cast<double>(engine::OBJECT_LIST_CAPACITY);
}
BENCHMARK(BM_ObjectListToRos);

void BM_Frame640x480ToRos(benchmark::State& state) {
  const Frame frame;
  b::RosScratch scratch;
  b::RosPointCloud2 msg{};
  const b::StampClock clock;
  for (auto _ : state) benchmark::DoNotOptimize(b::to_ros(frame.view, clock, scratch, msg));
  state.SetBytesProcessed(static_cast<std::int64_t>(state.iterations()) * 640 * 480 * 16);
}
BENCHMARK(BM_Frame640x480ToRos)->Unit(benchmark::kMicrosecond);

void BM_Frame640x480ThroughCyclone(benchmark::State& state) {
  const Frame frame;
  b::BridgeConfig config;
  config.domain = 222;
  const dds_entity_t domain = dds_create_domain(config.domain, b::cyclone_xml(config).c_str());
  const dds_entity_t pp = dds_create_participant(config.domain, nullptr, nullptr);
  const dds_entity_t topic = dds_create_topic(pp, &sensor_msgs_msg_dds__PointCloud2__desc,
                                              "rt/bench/points", nullptr, nullptr);
  dds_qos_t* qos = dds_create_qos();
  dds_qset_reliability(qos, DDS_RELIABILITY_BEST_EFFORT, 0);
  dds_qset_history(qos, DDS_HISTORY_KEEP_LAST, 1);
  const dds_entity_t writer = dds_create_writer(pp, topic, qos, nullptr);
  const dds_entity_t reader = dds_create_reader(pp, topic, qos, nullptr);
  dds_delete_qos(qos);
  b::RosScratch scratch;
  b::RosPointCloud2 msg{};
  const b::StampClock clock;
  for (auto _ : state) {
    (void)b::to_ros(frame.view, clock, scratch, msg);
    if (dds_write(writer, &msg) != 0) state.SkipWithError("dds_write failed");
    void* samples[1] = {nullptr};
    dds_sample_info_t info{};
    if (dds_take(reader, samples, &info, 1, 1) == 1) dds_return_loan(reader, samples, 1);
  }
  state.SetBytesProcessed(static_cast<std::int64_t>(state.iterations()) * 640 * 480 * 16);
  dds_delete(domain);
}
BENCHMARK(BM_Frame640x480ThroughCyclone)->Unit(benchmark::kMicrosecond);

}  // namespace

BENCHMARK_MAIN();
