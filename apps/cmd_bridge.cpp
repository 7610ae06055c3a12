// `orthoflow bridge dds`: a running graph's objects (and frames) on DDS with ROS 2's topic and type
// names, and learning commands from DDS into the graph (issue 23; bridge/, docs/DDS.md). Loopback
// by default; its own process beside the graph (`orthoflow run --ipc-learning [--publish-frames]`).
#include <atomic>
#include <chrono>
#include <csignal>
#include <cstdio>
#include <fstream>
#include <iostream>
#include <memory>
#include <random>
#include <string>
#include <thread>
#include <vector>

#include <sys/resource.h>
#include <unistd.h>

#include "apps/commands.hpp"
#include "apps/graph_run.hpp"
#include "core/file_output.hpp"
#include "engine/ipc_runtime.hpp"
#ifdef ORTHOFLOW_HAVE_DDS
#include "bridge/bridge_loop.hpp"
#endif

namespace orthoflow::apps {
namespace {

[[noreturn]] void fail(const std::string& message, int code = EXIT_FAILURE_GENERIC) {
  std::cerr << "bridge dds: " << message << "\n";
  throw CLI::RuntimeError(code);
}

std::atomic<bool> g_stop{false};
extern "C" void on_bridge_stop_signal(int /*signal*/) { g_stop.store(true); }

struct BridgeOptions {
  std::string config_file;
  std::string graph, interface, camera_frame;
  std::vector<std::string> peers;
  std::int64_t domain = -1;
  bool allow_network = false, accept_network_commands = false, frames = false;
  double max_frame_hz = -1.0;
  double seconds = 0.0;        // 0: until a signal
  double stats_every_s = 0.0;  // 0: only at the end
  std::string telemetry_json;
};

#ifdef ORTHOFLOW_HAVE_DDS
bridge::BridgeConfig config_of(const BridgeOptions& o) {
  bridge::BridgeConfig c;
  if (!o.config_file.empty()) {
    auto loaded = bridge::load_bridge_config(o.config_file);
    if (!loaded) fail(loaded.error(), EXIT_USAGE);
    c = *loaded;
  }
  // The command line over the file.
  if (!o.graph.empty()) c.graph = o.graph;
  if (o.domain >= 0) c.domain = static_cast<std::uint32_t>(o.domain);
  if (!o.interface.empty()) c.interface = o.interface;
  if (!o.camera_frame.empty()) c.camera_frame = o.camera_frame;
  if (!o.peers.empty()) c.peers = o.peers;
  c.allow_network = c.allow_network || o.allow_network;
  c.accept_network_commands = c.accept_network_commands || o.accept_network_commands;
  c.frames = c.frames || o.frames;
  if (o.max_frame_hz >= 0.0) c.max_frame_hz = o.max_frame_hz;
  if (auto ok = bridge::check_bridge_config(c); !ok) fail(ok.error(), EXIT_USAGE);
  return c;
}

std::uint64_t random_client_id() {
  std::random_device device;
  std::uint64_t id = 0;
  while (id == 0) id = (std::uint64_t{device()} << 32) ^ device();
  return id;
}

void print_report(const bridge::BridgeLoop& b) {
  const bridge::BridgeCounters& c = b.counters();
  const bridge::DdsStatus s = b.dds_status();
  std::printf(
      "bridge: objects %llu, frames %llu (thinned %llu, bad %llu), data %.1f MB, write errors "
      "%llu\n",
      static_cast<unsigned long long>(c.objects_out), static_cast<unsigned long long>(c.frames_out),
      static_cast<unsigned long long>(c.frames_thinned),
      static_cast<unsigned long long>(c.frames_bad), static_cast<double>(c.data_bytes_out) / 1e6,
      static_cast<unsigned long long>(c.write_errors));
  std::printf(
      "bridge: commands %llu: forwarded %llu, invalid %llu, no graph %llu, queue full %llu; acks "
      "%llu (timeouts %llu)\n",
      static_cast<unsigned long long>(c.commands_in),
      static_cast<unsigned long long>(c.commands_forwarded),
      static_cast<unsigned long long>(c.commands_invalid),
      static_cast<unsigned long long>(c.commands_no_graph),
      static_cast<unsigned long long>(c.commands_queue_full),
      static_cast<unsigned long long>(c.acks_out), static_cast<unsigned long long>(c.acks_timeout));
  std::printf(
      "dds: %u objects readers, %u points readers, %u command writers, %u inconsistent topics, "
      "%u commands lost, %u rejected\n",
      s.objects_readers, s.points_readers, s.command_writers, s.inconsistent_topics,
      s.commands_lost, s.commands_rejected);
  rusage usage{};
  (void)::getrusage(RUSAGE_SELF, &usage);
  const double cpu_s = static_cast<double>(usage.ru_utime.tv_sec + usage.ru_stime.tv_sec) +
                       1e-6 * static_cast<double>(usage.ru_utime.tv_usec + usage.ru_stime.tv_usec);
  const double wall_s = 1e-9 * static_cast<double>(b.stats().elapsed_ns.load());
  std::printf("cpu: %.2f s over %.1f s (%.1f %% of one core)\n", cpu_s, wall_s,
              wall_s > 0.0 ? 100.0 * cpu_s / wall_s : 0.0);
  std::printf("%s%s", engine::format_table(b.stats()).c_str(), b.ipc_lines().c_str());
  std::fflush(stdout);
}

void run_bridge(const BridgeOptions& o) {
  const bridge::BridgeConfig config = config_of(o);
  if (auto init = engine::init_ipc_runtime("orthoflow_dds_" + std::to_string(::getpid())); !init)
    fail(to_string(init.error()), init.error().code == engine::IpcError::Code::ROUDI_UNREACHABLE
                                      ? EXIT_NO_ROUDI
                                      : EXIT_FAILURE_GENERIC);
  auto opened = bridge::BridgeLoop::open(config, random_client_id());
  if (!opened) fail(opened.error());
  bridge::BridgeLoop& bridge = **opened;
  const bridge::BridgeTopics& t = bridge.topics();
  std::printf("bridge dds: graph %s, domain %u on %s: %s%s, %s -> %s\n", config.graph.c_str(),
              config.domain, config.interface.c_str(), t.objects.c_str(),
              config.frames ? (", " + t.points).c_str() : "", t.learning_commands.c_str(),
              t.learning_acks.c_str());
  std::fflush(stdout);
  g_stop.store(false);
  const auto previous_int = std::signal(SIGINT, on_bridge_stop_signal);
  const auto previous_term = std::signal(SIGTERM, on_bridge_stop_signal);
  const auto start = std::chrono::steady_clock::now();
  auto next_stats = start + std::chrono::duration<double>(o.stats_every_s);
  bool lost = false;
  while (!g_stop.load()) {
    const auto now = std::chrono::steady_clock::now();
    if (o.seconds > 0.0 && now - start >= std::chrono::duration<double>(o.seconds)) break;
    if (engine::ipc_roudi_lost() || !engine::probe_roudi()) {
      lost = true;
      break;
    }
    const std::int64_t now_ns =
        std::chrono::duration_cast<std::chrono::nanoseconds>(now.time_since_epoch()).count();
    if (bridge.pump(now_ns) == 0) std::this_thread::sleep_for(std::chrono::milliseconds(1));
    if (o.stats_every_s > 0.0 && now >= next_stats) {
      print_report(bridge);
      next_stats = now + std::chrono::duration<double>(o.stats_every_s);
    }
  }
  std::signal(SIGINT, previous_int);
  std::signal(SIGTERM, previous_term);
  print_report(bridge);
  if (!o.telemetry_json.empty()) {
    if (auto w = core::write_whole_file(o.telemetry_json, engine::to_json(bridge.stats()) + "\n");
        !w)
      fail("cannot write " + w.error());
  }
  if (lost) fail(roudi_lost_text("bridging to DDS"), EXIT_ROUDI_LOST);
}
#else
void run_bridge(const BridgeOptions&) {
  fail("this orthoflow was built without Cyclone DDS (cyclonedds-dev, cyclonedds-tools)");
}
#endif

}  // namespace

void add_bridge_command(CLI::App& app) {
  auto* bridge = app.add_subcommand("bridge", "Bridges to other middleware (dds)");
  bridge->require_subcommand(1);
  auto o = std::make_shared<BridgeOptions>();
  auto* cmd = bridge->add_subcommand(
      "dds",
      "A running graph's objects and frames on DDS as ROS 2 topics; learning commands from "
      "DDS into it (docs/DDS.md)");
  cmd->add_option("--config", o->config_file, "YAML settings (docs/DDS.md); options override it")
      ->check(CLI::ExistingFile);
  cmd->add_option("--graph", o->graph,
                  "The graph's name (orthoflow/<graph>/...; default tabletop)");
  cmd->add_option("--domain", o->domain, "DDS domain id, 0..232 (default 0)")
      ->check(CLI::Range(0, 232));
  cmd->add_option("--interface", o->interface,
                  "Network interface name or address (default lo: this host only)");
  cmd->add_option("--peer", o->peers, "A peer's address for unicast discovery (repeat)");
  cmd->add_flag(
      "--allow-network", o->allow_network,
      "Allow an interface other than loopback (no DDS Security set up: anyone there reads)");
  cmd->add_flag("--accept-network-commands", o->accept_network_commands,
                "Take learning commands on a non-loopback interface (unauthenticated)");
  cmd->add_flag("--frames", o->frames, "Also bridge orthoflow/<graph>/frames as PointCloud2");
  cmd->add_option("--max-frame-hz", o->max_frame_hz, "Thin frames to this rate (default 30)")
      ->check(CLI::Range(0.0, 1000.0));
  cmd->add_option("--camera-frame", o->camera_frame,
                  "header.frame_id (default camera_depth_optical_frame)");
  cmd->add_option("--seconds", o->seconds, "Stop after this long (default: at SIGINT / SIGTERM)");
  cmd->add_option("--stats-every", o->stats_every_s, "Print the counters every S seconds");
  cmd->add_option("--telemetry-json", o->telemetry_json,
                  "Write the bridge's telemetry (the engine's JSON) at exit");
  cmd->callback([o] { run_bridge(*o); });
}

}  // namespace orthoflow::apps
