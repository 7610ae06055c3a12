// `orthoflow ipc send TOPIC`: publishes synthetic frames through the zero-copy path (loan, fill in
// place, publish), for smoke tests, `ipc echo` demos, tests and the IPC benchmark's sanity checks.
#include <csignal>
#include <iostream>
#include <thread>

#include "apps/commands.hpp"
#include "engine/frame_payload.hpp"
#include "engine/ipc_nodes.hpp"

namespace orthoflow::apps {

namespace {

struct SendArgs {
  std::string topic;
  std::uint64_t frames = 10;
  std::uint32_t width = 64, height = 48;
  double period_ms = 10;
  int version = engine::FRAME_VERSION;  ///< override to simulate another build (mismatch tests)
  std::uint64_t history = 0;
  std::uint64_t max_bytes = 0;  ///< 0 = this frame's size
  std::string roudi_config;     ///< RouDi TOML; empty = ask RouDi
  std::int64_t wait_subscribers_ms =
      0;  ///< wait this long for a subscriber before sending (0 = no wait)
};

std::atomic<bool> send_stop{false};
extern "C" void on_send_signal(int /*sig*/) { send_stop.store(true); }

// Frame k: point i at (k + i, 2i, 3i) metres, so a receiver can check every value.
void fill_frame(std::span<std::byte> chunk, const SendArgs& a, std::uint64_t k) {
  auto span = engine::layout_frame(chunk, a.width, a.height, 0);
  if (!span) return;
  span->header->frame_id = k;
  span->header->sensor_stamp_ns = static_cast<std::int64_t>(k) * 1000;
  span->header->host_stamp_ns = std::chrono::duration_cast<std::chrono::nanoseconds>(
                                    std::chrono::steady_clock::now().time_since_epoch())
                                    .count();
  span->header->version = static_cast<std::uint16_t>(a.version);
  for (std::size_t i = 0; i < span->points.x.size(); ++i) {
    span->points.x[i] = static_cast<float>(k + i);
    span->points.y[i] = static_cast<float>(2 * i);
    span->points.z[i] = static_cast<float>(3 * i);
  }
}

// Waits (bounded) until a subscriber is connected, so that scripted receivers see every frame.
void wait_for_subscribers(const engine::IpcPublisher& publisher, std::int64_t wait_ms) {
  const auto until = std::chrono::steady_clock::now() + std::chrono::milliseconds(wait_ms);
  while (wait_ms > 0 && !publisher.has_subscribers() && !send_stop.load()) {
    if (std::chrono::steady_clock::now() > until) {
      std::cerr << "orthoflow ipc send: no subscriber on " << publisher.topic() << " within "
                << wait_ms << " ms\n";
      throw CLI::RuntimeError(EXIT_FAILURE_GENERIC);
    }
    if (!engine::probe_roudi())
      throw(std::cerr << "orthoflow ipc send: RouDi lost\n", CLI::RuntimeError(22));
    std::this_thread::sleep_for(std::chrono::milliseconds(2));
  }
}

int send(const SendArgs& a) {
  auto topic = engine::parse_topic(a.topic);
  if (!topic) throw(std::cerr << to_string(topic.error()) << "\n", CLI::RuntimeError(EXIT_USAGE));
  const std::size_t bytes = engine::frame_payload_bytes(a.width, a.height, 0);
  if (auto init = engine::init_ipc_runtime("orthoflow_send_" + std::to_string(::getpid())); !init) {
    std::cerr << "orthoflow ipc send: " << to_string(init.error()) << "\n";
    throw CLI::RuntimeError(20);
  }
  std::signal(SIGINT, on_send_signal);
  std::signal(SIGTERM, on_send_signal);
  auto pools = a.roudi_config.empty() ? engine::query_roudi_pools(std::chrono::milliseconds(3000))
                                      : engine::load_roudi_pools(a.roudi_config);
  if (!pools)
    throw(std::cerr << to_string(pools.error()) << "\n", CLI::RuntimeError(EXIT_FAILURE_GENERIC));
  engine::IpcPublisherConfig config{{engine::FRAME_TYPE_ID, static_cast<std::uint16_t>(a.version)},
                                    a.max_bytes > 0 ? a.max_bytes : bytes,
                                    a.history,
                                    false};
  auto publisher = engine::IpcPublisher::create(*topic, config, *pools);
  if (!publisher) {
    std::cerr << "orthoflow ipc send: " << to_string(publisher.error()) << "\n";
    throw CLI::RuntimeError(publisher.error().code == engine::IpcError::Code::NO_FITTING_POOL ? 21
                                                                                              : 1);
  }
  wait_for_subscribers(**publisher, a.wait_subscribers_ms);
  std::uint64_t failures = 0;
  for (std::uint64_t k = 0; k < a.frames && !send_stop.load(); ++k) {
    if (!engine::probe_roudi()) {
      std::cerr << "orthoflow ipc send: RouDi lost after " << k << " frames\n";
      throw CLI::RuntimeError(22);
    }
    auto chunk = (*publisher)->loan(bytes);
    if (!chunk) {
      if (failures++ == 0) std::cerr << "orthoflow ipc send: " << to_string(chunk.error()) << "\n";
    } else {
      fill_frame(*chunk, a, k);
      if (auto sent = (*publisher)->publish(*chunk); !sent) ++failures;
    }
    std::this_thread::sleep_for(
        std::chrono::microseconds(static_cast<std::int64_t>(a.period_ms * 1000)));
  }
  std::cout << "sent " << (*publisher)->counters().samples.load() << " failed " << failures
            << std::endl;
  return 0;
}

}  // namespace

void add_ipc_send(CLI::App& ipc) {
  static SendArgs args;
  auto* cmd =
      ipc.add_subcommand("send", "publish synthetic frames (loaned, filled in place) on TOPIC");
  cmd->add_option("topic", args.topic, "service/instance/event")->required();
  cmd->add_option("--frames", args.frames, "frames to send");
  cmd->add_option("--width", args.width, "points per row")->check(CLI::Range(1, 4096));
  cmd->add_option("--height", args.height, "rows")->check(CLI::Range(1, 4096));
  cmd->add_option("--period-ms", args.period_ms, "pause between frames")
      ->check(CLI::Range(0.0, 10000.0));
  cmd->add_option("--version", args.version, "payload version to write (default: this build's)")
      ->check(CLI::Range(0, 65535));
  cmd->add_option("--history", args.history, "samples kept for late subscribers")
      ->check(CLI::Range(0, 16));
  cmd->add_option("--max-bytes", args.max_bytes, "largest payload to check against the pools");
  cmd->add_option("--config", args.roudi_config,
                  "RouDi TOML the pools come from (default: ask RouDi)");
  cmd->add_option("--wait-subscribers-ms", args.wait_subscribers_ms,
                  "wait for a subscriber first (exit 1 on timeout)")
      ->check(CLI::Range(0, 60000));
  cmd->callback([] { send(args); });
}

}  // namespace orthoflow::apps
