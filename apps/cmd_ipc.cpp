// `orthoflow ipc ...`: operate the iceoryx transport (docs/IPC.md). Exit codes beyond commands.hpp:
// 20 RouDi unreachable, 21 RouDi's pools do not fit the topics, 22 RouDi lost while running.
#include <unistd.h>
#include <csignal>
#include <cstring>
#include <iostream>
#include <map>
#include <thread>

#include "apps/commands.hpp"
#include "apps/graph_run.hpp"
#include "engine/arm_state_payload.hpp"
#include "engine/frame_payload.hpp"
#include "engine/ipc_nodes.hpp"
#include "engine/object_list_payload.hpp"

namespace orthoflow::apps {

namespace {

std::atomic<bool> stop_flag{false};
extern "C" void on_signal(int /*sig*/) { stop_flag.store(true); }

[[noreturn]] void fail(int code, const std::string& message) {
  std::cerr << "orthoflow ipc: " << message << "\n";
  throw CLI::RuntimeError(code);
}

int exit_code_of(const engine::IpcError& error) {
  switch (error.code) {
    case engine::IpcError::Code::ROUDI_UNREACHABLE:
      return EXIT_NO_ROUDI;
    case engine::IpcError::Code::ROUDI_LOST:
      return EXIT_ROUDI_LOST;
    case engine::IpcError::Code::NO_FITTING_POOL:
      return EXIT_POOLS;
    default:
      return EXIT_FAILURE_GENERIC;
  }
}

template <class T>
T value_or_fail(Result<T, engine::IpcError>&& result) {
  if (!result) fail(exit_code_of(result.error()), to_string(result.error()));
  return std::move(*result);
}

void start_runtime(const char* role) {
  auto init =
      engine::init_ipc_runtime(std::string("orthoflow_") + role + "_" + std::to_string(::getpid()));
  if (!init) fail(exit_code_of(init.error()), to_string(init.error()));
  std::signal(SIGINT, on_signal);
  std::signal(SIGTERM, on_signal);  // RouDi SIGTERMs its apps when it shuts down
}

/// One demand per IPC node of a graph file: payload bytes and chunks it can hold at once.
struct Demand {
  std::string topic;
  std::uint64_t bytes = 0;
  std::uint64_t chunks = 0;
};

// The file is validated as `graph check` does (every graph error, cycles included, with file and
// line, exit 2): a graph that cannot run gets no RouDi configuration.
std::vector<Demand> demands_of(const std::string& file) {
  const auto registry = make_graph_registry();
  const auto graph = load_graph_or_throw(file, registry, engine::BuildMode::CHECK);
  const engine::GraphSpec* spec = &graph->spec;
  std::vector<Demand> demands;
  for (const auto& node : spec->nodes) {
    auto get = [&](const char* key, std::int64_t fallback) {
      return node.params.integer(key, fallback, 0, INT64_MAX);
    };
    std::string topic;
    for (const auto& e : node.params.entries()) topic = e.key == "topic" ? e.value : topic;
    if (node.kind == "ipc_publish") {
      // 8 chunks loaned at once at most (iceoryx), plus the publisher's history.
      const auto bytes = get("max_bytes", static_cast<std::int64_t>(spec->block_bytes));
      const auto history = get("history", 0);
      if (!bytes || !history) fail(EXIT_BAD_INPUT, file + ": bad ipc_publish parameter");
      demands.push_back(
          {topic, static_cast<std::uint64_t>(*bytes), 8 + static_cast<std::uint64_t>(*history)});
    } else if (node.kind == "ipc_subscribe") {
      // One chunk per pool block (FrameRef) plus the queue.
      const auto depth = get("depth", 1);
      if (!depth) fail(EXIT_BAD_INPUT, file + ": bad ipc_subscribe parameter");
      demands.push_back({topic, 0, spec->blocks + static_cast<std::uint64_t>(*depth)});
    }
  }
  return demands;
}

void run_config(const std::vector<std::string>& files) {
  std::uint64_t held = 0;
  std::map<std::uint64_t, std::uint64_t>
      pools;  // payload bytes (64-byte multiple + alignment slack) -> count
  std::vector<Demand> publishers;
  for (const auto& file : files) {
    for (auto& d : demands_of(file)) {
      if (d.bytes > 0)
        publishers.push_back(d);
      else
        held += d.chunks;  // subscribers hold chunks of every publisher they listen to
    }
  }
  for (const auto& p : publishers) {
    // Slack for the 64-byte payload alignment inside the chunk (iox::mepoo::ChunkSettings).
    const std::uint64_t size = (p.bytes + 63) / 64 * 64 + 64;
    pools[size] += p.chunks + (held > 0 ? held : 16);
  }
  std::cout << "# RouDi pools for " << files.size()
            << " graph file(s); start: iox-roudi -c THIS_FILE\n"
            << "[general]\nversion = 1\n\n[[segment]]\n\n";
  std::cout << "[[segment.mempool]]\nsize = 1024\ncount = 64\n";
  for (const auto& [size, count] : pools)
    std::cout << "\n[[segment.mempool]]\nsize = " << size << "\ncount = " << count << "\n";
}

void run_doctor(const std::string& config, const std::vector<std::string>& files) {
  if (auto probe = engine::probe_roudi(); !probe) fail(EXIT_NO_ROUDI, to_string(probe.error()));
  std::cout << "RouDi: reachable on " << engine::ROUDI_SOCKET_PATH << "\n";
  start_runtime("doctor");
  auto pools =
      value_or_fail(config.empty() ? engine::query_roudi_pools(std::chrono::milliseconds(3000))
                                   : engine::load_roudi_pools(config));
  for (const auto& pool : pools)
    std::cout << "pool: " << pool.payload_bytes << " B x " << pool.count << "\n";
  bool ok = true;
  for (const auto& file : files) {
    for (const auto& d : demands_of(file)) {
      if (d.bytes == 0) continue;
      auto fits =
          engine::check_pool_fits(pools, d.bytes, engine::PAYLOAD_ALIGNMENT, file + " " + d.topic);
      std::cout << (fits ? "ok:   " : "FAIL: ") << d.topic << " " << d.bytes << " B"
                << (fits ? "" : " (" + fits.error().message + ")") << "\n";
      ok = ok && fits;
    }
  }
  if (!ok) throw CLI::RuntimeError(EXIT_POOLS);
}

void print_sample(std::span<const std::byte> bytes, std::uint64_t sequence,
                  const std::string& type) {
  std::cout << "seq " << sequence << " bytes " << bytes.size() << " type " << type;
  if (type == "frame") {
    auto frame = engine::view_frame(bytes);
    if (!frame) {
      std::cout << " invalid: " << frame.error().to_string() << "\n";
      return;
    }
    const auto& h = *frame->header;
    std::cout << " frame " << h.frame_id << " " << h.width << "x" << h.height << " sensor_ns "
              << h.sensor_stamp_ns << " host_ns " << h.host_stamp_ns << "\n";
    return;
  }
  if (type == "arm_state") {
    engine::ArmStatePayload arm;
    std::memcpy(static_cast<void*>(&arm), bytes.data(), std::min(bytes.size(), sizeof(arm)));
    std::cout << " cycle " << arm.cycle << " state " << arm.arm_state << " joints";
    for (double q : arm.joints_deg) std::cout << ' ' << q;
    std::cout << " xyz " << arm.position_m[0] << ' ' << arm.position_m[1] << ' '
              << arm.position_m[2] << ((arm.flags & engine::ARM_ESTOP) != 0U ? " estop" : "")
              << ((arm.flags & engine::ARM_FAULT) != 0U ? " fault" : "") << "\n";
    return;
  }
  engine::ObjectListPayload list;
  std::memcpy(static_cast<void*>(&list), bytes.data(), std::min(bytes.size(), sizeof(list)));
  const auto count = std::min(list.count, engine::OBJECT_LIST_CAPACITY);
  std::cout << " frame " << list.frame_id << " objects " << count << "\n";
  for (std::uint32_t i = 0; i < count; ++i) {
    const auto& o = list.objects[i];
    std::cout << "  track " << o.track_id << " label " << o.label.view() << " score " << o.score
              << (o.unknown ? " unknown" : "") << " centroid " << o.centroid[0] << " "
              << o.centroid[1] << " " << o.centroid[2] << " points " << o.point_count << "\n";
  }
}

struct EchoArgs {
  std::string topic, type = "frame", policy = "queue";
  std::uint64_t count = 0, depth = 16;
  std::int64_t timeout_ms = 0,
               process_ms = 0;  ///< process_ms: simulated work per sample (slow consumer)
};

void run_echo(const EchoArgs& a) {
  const std::string& topic_text = a.topic;
  const std::string& type = a.type;
  const std::uint64_t count = a.count;
  const std::int64_t timeout_ms = a.timeout_ms;
  auto topic = value_or_fail(engine::parse_topic(topic_text));
  auto payload_type = type == "arm_state"
                          ? Result<engine::IpcPayloadType, std::string>(engine::IpcPayloadType{
                                engine::ARM_STATE_TYPE_ID, engine::ARM_STATE_VERSION})
                          : engine::ipc_payload_type(type);
  if (!payload_type) fail(EXIT_USAGE, payload_type.error());
  start_runtime("echo");
  engine::IpcSubscriberConfig config{
      *payload_type, a.policy == "latest" ? engine::IpcPolicy::LATEST : engine::IpcPolicy::QUEUE,
      a.depth, 0};
  auto subscriber = value_or_fail(engine::IpcSubscriber::create(topic, config));
  std::uint64_t seen = 0;
  auto last = std::chrono::steady_clock::now();
  while (!stop_flag.load() && (count == 0 || seen < count)) {
    auto taken = subscriber->take();
    if (!taken) {
      std::cout << "rejected: " << to_string(taken.error()) << std::endl;
    } else if (taken->has_value()) {
      print_sample((*taken)->bytes(), (*taken)->sequence(), type);
      ++seen;
      if (a.process_ms > 0) std::this_thread::sleep_for(std::chrono::milliseconds(a.process_ms));
      last = std::chrono::steady_clock::now();
      continue;
    }
    if (!engine::probe_roudi()) fail(EXIT_ROUDI_LOST, "RouDi lost while echoing " + topic_text);
    if (timeout_ms > 0 &&
        std::chrono::steady_clock::now() - last > std::chrono::milliseconds(timeout_ms))
      break;
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
  std::cout << "received " << seen << " dropped " << subscriber->counters().dropped.load()
            << " rejected " << subscriber->counters().rejected.load() << std::endl;
}

}  // namespace

void add_ipc_send(CLI::App& ipc);

void add_ipc_command(CLI::App& app) {
  auto* ipc =
      app.add_subcommand("ipc", "iceoryx transport: config, doctor, echo, send, run (docs/IPC.md)");
  ipc->require_subcommand(1);
  auto* config =
      ipc->add_subcommand("config", "print a RouDi TOML with pools sized for the graphs' topics");
  static std::vector<std::string> files;
  config->add_option("graphs", files, "graph YAML files")->required()->check(CLI::ExistingFile);
  config->callback([] { run_config(files); });
  auto* doctor =
      ipc->add_subcommand("doctor", "RouDi reachable? pools fit the graphs' topics? (exit 20/21)");
  static std::string roudi_config;
  static std::vector<std::string> doctor_files;
  doctor->add_option("--config", roudi_config, "RouDi TOML (default: ask RouDi)")
      ->check(CLI::ExistingFile);
  doctor->add_option("graphs", doctor_files, "graph YAML files")->check(CLI::ExistingFile);
  doctor->callback([] { run_doctor(roudi_config, doctor_files); });
  auto* echo = ipc->add_subcommand("echo", "print what flows on TOPIC");
  static EchoArgs echo_args;
  echo->add_option("topic", echo_args.topic, "service/instance/event")->required();
  echo->add_option("--type", echo_args.type, "frame|objects|arm_state")
      ->check(CLI::IsMember({"frame", "objects", "arm_state"}));
  echo->add_option("--count", echo_args.count, "stop after N samples (0 = endless)");
  echo->add_option("--timeout-ms", echo_args.timeout_ms,
                   "stop after this long without data (0 = never)");
  echo->add_option("--policy", echo_args.policy, "latest|queue")
      ->check(CLI::IsMember({"latest", "queue"}));
  echo->add_option("--depth", echo_args.depth, "queue depth (policy queue)")
      ->check(CLI::Range(1, 256));
  echo->add_option("--process-ms", echo_args.process_ms,
                   "pause after each sample (simulates a slow consumer)")
      ->check(CLI::Range(0, 10000));
  echo->callback([] { run_echo(echo_args); });
  add_ipc_send(*ipc);
  // `ipc run` is `graph run` (same registry: every kind, so the shipped two-process graphs run)
  // with the IPC exit codes: 20 when no RouDi answers before the start, 22 when it is lost while
  // running.
  auto* run = ipc->add_subcommand(
      "run",
      "run a graph file like `graph run` (e.g. graphs/sensor.yaml); exit 20 without RouDi, "
      "22 if RouDi is lost");
  static GraphRunArgs run_args;
  run_args.command = "orthoflow ipc run";
  run->add_option("graph", run_args.file, "graph YAML")->required()->check(CLI::ExistingFile);
  run->add_option("--frames", run_args.frames, "stop after N frames");
  run->callback([] {
    if (auto probe = engine::probe_roudi(); !probe) fail(EXIT_NO_ROUDI, to_string(probe.error()));
    run_graph_file(run_args);
  });
}

}  // namespace orthoflow::apps
