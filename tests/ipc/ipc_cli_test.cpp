// Multi-process IPC tests: every test starts its own RouDi in a private mount namespace (fresh
// tmpfs on /dev/shm and /tmp) and drives `orthoflow ipc send|echo` child processes; every wait is
// bounded.
#include <gtest/gtest.h>
#include <signal.h>

#include <cstdio>
#include <fstream>
#include <thread>

#include "engine/frame_payload.hpp"
#include "engine/ipc_pubsub.hpp"
#include "engine/ipc_runtime.hpp"
#include "tests/ipc/roudi_sandbox.hpp"

namespace orthoflow::tests {
namespace {

using namespace std::chrono_literals;

const std::string CONFIG = ORTHOFLOW_SOURCE_DIR "/config/roudi_test.toml";
const std::string TOPIC = "orthoflow/test/frames";

// Variadic: the scenario lambda's commas are not argument separators.
#define RUN_ISOLATED(...)                                   \
  do {                                                      \
    const Outcome outcome = run_isolated(__VA_ARGS__, 25s); \
    if (outcome.skipped) GTEST_SKIP() << outcome.reason;    \
    EXPECT_EQ(outcome.failures, "");                        \
  } while (false)

// Value of "<key> N" in `text` (the echo/send summaries), or -1.
long long number_after(const std::string& text, const std::string& key) {
  // A plain scan (std::regex trips GCC 12's -Wmaybe-uninitialized under the sanitizers).
  const std::string pattern = key + " ";
  for (std::size_t at = text.find(pattern); at != std::string::npos;
       at = text.find(pattern, at + 1)) {
    std::size_t digit = at + pattern.size(), end = digit;
    while (end < text.size() && text[end] >= '0' && text[end] <= '9') ++end;
    if (end > digit) return std::stoll(text.substr(digit, end - digit));
  }
  return -1;
}

void write_file(const std::string& path, const std::string& text) { std::ofstream(path) << text; }

std::vector<std::string> send_args(std::uint64_t frames, double period_ms) {
  return {"ipc",
          "send",
          TOPIC,
          "--frames",
          std::to_string(frames),
          "--period-ms",
          std::to_string(period_ms),
          "--config",
          CONFIG,
          "--wait-subscribers-ms",
          "5000"};
}

TEST(IpcCli, FramesHandedOverInOrderWithTheirSizes) {
  RUN_ISOLATED([](Sandbox& box) {
    if (box.start_roudi() < 0) return;
    const pid_t echo = box.spawn_orthoflow(
        "echo", {"ipc", "echo", TOPIC, "--count", "20", "--depth", "32", "--timeout-ms", "5000"});
    const pid_t send = box.spawn_orthoflow("send", send_args(20, 1));
    const ProcResult s = box.wait(send, 8s), e = box.wait(echo, 8s);
    box.check(
        s.exit_code == 0 && number_after(s.out, "sent") == 20 && number_after(s.out, "failed") == 0,
        "send: 20 frames, none failed", s);
    box.check(e.exit_code == 0, "echo exits 0", e);
    const auto frames = lines_with(e.out, " frame ");
    box.check(frames.size() == 20, "echo prints 20 frames", e);
    const std::string bytes = std::to_string(engine::frame_payload_bytes(64, 48, 0));
    for (std::size_t k = 0; k < frames.size(); ++k) {
      const std::string expected = "seq " + std::to_string(k) + " bytes " + bytes +
                                   " type frame frame " + std::to_string(k) + " 64x48 sensor_ns " +
                                   std::to_string(k * 1000) + " ";
      box.check(frames[k].rfind(expected, 0) == 0,
                "line " + std::to_string(k) + " is '" + frames[k] +
                    "', expected it to start with '" + expected + "'");
    }
    box.check(number_after(e.out, "received") == 20 && number_after(e.out, "dropped") == 0 &&
                  number_after(e.out, "rejected") == 0,
              "echo summary: 20 received, 0 dropped, 0 rejected", e);
  });
}

TEST(IpcCli, LatestWinsDropsUnderASlowConsumer) {
  RUN_ISOLATED([](Sandbox& box) {
    if (box.start_roudi() < 0) return;
    const pid_t echo = box.spawn_orthoflow("echo", {"ipc", "echo", TOPIC, "--policy", "latest",
                                                    "--process-ms", "40", "--timeout-ms", "700"});
    const pid_t send = box.spawn_orthoflow("send", send_args(50, 2));
    const ProcResult s = box.wait(send, 8s), e = box.wait(echo, 10s);
    box.check(s.exit_code == 0 && number_after(s.out, "failed") == 0, "send exits 0, none failed",
              s);
    const long long received = number_after(e.out, "received"),
                    dropped = number_after(e.out, "dropped");
    box.check(e.exit_code == 0 && received > 0 && dropped > 0,
              "slow latest-wins consumer drops frames", e);
    long long previous = -1, first = -1;
    for (const auto& line : lines_with(e.out, " frame ")) {
      const long long id = number_after(line, "type frame frame");
      box.check(id > previous, "frame ids increase: " + line);
      previous = id;
      first = first < 0 ? id : first;
    }
    // Frames discarded before the first take are invisible to the subscriber (it cannot tell them
    // from frames sent before it connected); from the first one on, every frame is accounted for.
    box.check(
        first >= 0 && received + dropped == 50 - first,
        "from the first received frame on, every frame is either received or counted as dropped",
        e);
    box.check(previous == 49, "the newest frame (49) wins at the end", e);
  });
}

TEST(IpcCli, TypeAndVersionMismatchAreRejectedClearly) {
  RUN_ISOLATED([](Sandbox& box) {
    if (box.start_roudi() < 0) return;
    pid_t echo = box.spawn_orthoflow("echo_v", {"ipc", "echo", TOPIC, "--timeout-ms", "600"});
    auto args = send_args(5, 1);
    args.insert(args.end(), {"--version", "99"});
    ProcResult s = box.wait(box.spawn_orthoflow("send_v", args), 8s), e = box.wait(echo, 8s);
    box.check(s.exit_code == 0, "send of version 99 exits 0", s);
    box.check(e.exit_code == 0 && number_after(e.out, "received") == 0 &&
                  number_after(e.out, "rejected") == 5 &&
                  lines_with(e.out, "rejected: WRONG_VERSION").size() == 5 &&
                  e.out.find("(99, 1)") != std::string::npos,
              "version 99 chunks rejected as WRONG_VERSION naming found and expected", e);
    echo = box.spawn_orthoflow("echo_t",
                               {"ipc", "echo", TOPIC, "--type", "objects", "--timeout-ms", "600"});
    s = box.wait(box.spawn_orthoflow("send_t", send_args(5, 1)), 8s);
    e = box.wait(echo, 8s);
    box.check(s.exit_code == 0, "send of frames exits 0", s);
    box.check(e.exit_code == 0 && number_after(e.out, "received") == 0 &&
                  number_after(e.out, "rejected") == 5 &&
                  lines_with(e.out, "rejected: WRONG_TYPE").size() == 5,
              "frames on an objects subscriber rejected as WRONG_TYPE", e);
  });
}

TEST(IpcCli, RouDiAbsentIsAnErrorWithinOneSecond) {
  RUN_ISOLATED([](Sandbox& box) {
    for (const auto& args :
         {send_args(5, 1), std::vector<std::string>{"ipc", "echo", TOPIC, "--count", "1"},
          std::vector<std::string>{"ipc", "doctor"}}) {
      const ProcResult p = box.wait(box.spawn_orthoflow("absent", args), 5s);
      box.check(p.exit_code == 20 && p.err.find("ROUDI_UNREACHABLE") != std::string::npos &&
                    p.err.find("/tmp/roudi") != std::string::npos,
                "ipc " + args[1] + " without RouDi: exit 20 naming the socket", p);
      std::fprintf(stderr, "ipc %s without RouDi: exit %d after %.3f s\n", args[1].c_str(),
                   p.exit_code, p.seconds);
      box.check(p.seconds < 1.0, "ipc " + args[1] + " without RouDi fails within 1 s (took " +
                                     std::to_string(p.seconds) + " s)");
    }
  });
}

// BuildMode::CHECK: with no RouDi in the namespace `graph check` validates the two-process graph
// files completely; `graph run` still registers with RouDi and so fails, naming it.
TEST(IpcCli, GraphCheckNeedsNoRouDiGraphRunDoes) {
  RUN_ISOLATED([](Sandbox& box) {
    const std::string graphs = ORTHOFLOW_SOURCE_DIR "/graphs/";
    for (const std::string file : {"perception.yaml", "sensor.yaml"}) {
      const ProcResult p =
          box.wait(box.spawn_orthoflow("check", {"graph", "check", graphs + file}), 5s);
      box.check(p.exit_code == 0 && p.out.find(file + ": ok (") != std::string::npos,
                "graph check " + file + " without RouDi: exit 0, ok", p);
    }
    const ProcResult run =
        box.wait(box.spawn_orthoflow("run", {"graph", "run", graphs + "perception.yaml"}), 5s);
    box.check(
        run.exit_code == 2 && run.err.find("node 'frames': ROUDI_UNREACHABLE") != std::string::npos,
        "graph run perception.yaml without RouDi: exit 2, ROUDI_UNREACHABLE", run);
  });
}

// BuildMode::RUN: `graph run` connects its IPC nodes: a subscriber graph takes 5 frames from `ipc
// send`, a publisher graph whose roudi_config names the RouDi TOML file offers its topic.
TEST(IpcCli, GraphRunConnectsItsIpcNodes) {
  RUN_ISOLATED([](Sandbox& box) {
    if (box.start_roudi() < 0) return;
    const std::string header = "graph:\n  pool: {block_bytes: 4096, blocks: 4}\nnodes:\n";
    write_file("/tmp/sub.yaml",
               header + "  - {name: frames, kind: ipc_subscribe, params: {topic: " + TOPIC +
                   ", policy: queue, depth: 16, frames: 5, idle_ms: 5000}}\n"
                   "  - {name: sink, kind: pass}\nedges:\n  - frames.out -> sink.in\n");
    write_file("/tmp/pub.yaml",
               header +
                   "  - {name: src, kind: ticker, params: {frames: 3}}\n"
                   "  - {name: out, kind: ipc_publish, params: {topic: orthoflow/test/ticks, "
                   "roudi_config: " +
                   CONFIG + "}}\nedges:\n  - src.out -> out.in\n");
    const pid_t sub = box.spawn_orthoflow("graph_sub", {"graph", "run", "/tmp/sub.yaml"});
    const pid_t send = box.spawn_orthoflow("send", send_args(50, 5));
    const ProcResult r = box.wait(sub, 10s), s = box.wait(send, 10s);
    // The source ends after its 5 frames; without data it would end only after idle_ms (5 s).
    box.check(
        r.exit_code == 0 && r.out.find("source ended") != std::string::npos && r.seconds < 4.0,
        "graph run of a subscriber graph: 5 frames, then the source ends", r);
    box.check(s.exit_code == 0, "send exits 0", s);
    const ProcResult p =
        box.wait(box.spawn_orthoflow("graph_pub", {"graph", "run", "/tmp/pub.yaml"}), 10s);
    box.check(p.exit_code == 0 && p.out.find("source ended") != std::string::npos,
              "graph run of a publisher graph with roudi_config", p);
  });
}

TEST(IpcCli, RouDiKilledWhileRunningGivesExit22) {
  RUN_ISOLATED([](Sandbox& box) {
    const pid_t roudi = box.start_roudi();
    if (roudi < 0) return;
    const pid_t echo = box.spawn_orthoflow("echo", {"ipc", "echo", TOPIC});
    const pid_t send = box.spawn_orthoflow("send", send_args(100000, 5));
    box.check(box.wait_for_output(echo, " frame 5 ", 8s),
              "echo sees frame 5 before RouDi is killed");
    ::kill(roudi, SIGKILL);
    const ProcResult s = box.wait(send, 3s), e = box.wait(echo, 3s);
    box.check(s.exit_code == 22 && s.err.find("RouDi lost") != std::string::npos,
              "send exits 22 (RouDi lost)", s);
    box.check(e.exit_code == 22 && e.err.find("RouDi lost") != std::string::npos,
              "echo exits 22 (RouDi lost)", e);
  });
}

TEST(IpcCli, ProducerOutlivesAConsumerKilledWithSigkill) {
  RUN_ISOLATED([](Sandbox& box) {
    if (box.start_roudi() < 0) return;
    const pid_t echo = box.spawn_orthoflow("echo", {"ipc", "echo", TOPIC, "--depth", "16"});
    const pid_t send = box.spawn_orthoflow("send", send_args(150, 4));
    box.check(box.wait_for_output(echo, " frame 10 ", 8s),
              "echo sees frame 10 before it is killed");
    ::kill(echo, SIGKILL);
    const ProcResult e = box.wait(echo, 2s), s = box.wait(send, 8s);
    box.check(e.signal == SIGKILL, "echo died of SIGKILL", e);
    box.check(s.exit_code == 0 && number_after(s.out, "sent") == 150 &&
                  number_after(s.out, "failed") == 0,
              "send goes on: 150 sent, no loan failed (chunks of the dead consumer do not run the "
              "pool dry)",
              s);
  });
}

TEST(IpcCli, NoFittingPoolIsExit21NotAnAbort) {
  RUN_ISOLATED([](Sandbox& box) {
    if (box.start_roudi() < 0) return;
    // A 640x480 frame (3.7 MB) exceeds roudi_test.toml's largest pool (64 KiB): iceoryx would
    // abort.
    const std::vector<std::string> big{"ipc",      "send", TOPIC,      "--width", "640",
                                       "--height", "480",  "--frames", "1"};
    auto with_config = big;
    with_config.insert(with_config.end(), {"--config", CONFIG});
    for (const auto& args : {with_config, big}) {
      const ProcResult p = box.wait(box.spawn_orthoflow("big", args), 8s);
      box.check(p.exit_code == 21 && p.signal == 0 &&
                    p.err.find("NO_FITTING_POOL") != std::string::npos &&
                    p.err.find("65536") != std::string::npos,
                std::string(
                    "640x480 frame: exit 21 NO_FITTING_POOL naming the largest pool, pools from ") +
                    (args.size() > big.size() ? "the TOML file" : "RouDi's introspection"),
                p);
    }
  });
}

TEST(IpcCli, PoolExhaustionIsAnErrorNotAnAbort) {
  RUN_ISOLATED([](Sandbox& box) {
    if (box.start_roudi() < 0) return;
    auto runtime = engine::init_ipc_runtime("exhaust_test");
    box.check(runtime.has_value(), "init_ipc_runtime with RouDi up");
    auto pools = engine::load_roudi_pools(CONFIG);
    box.check(pools.has_value(), "pools of roudi_test.toml");
    if (!runtime || !pools) return;
    // 60000-byte payloads only fit the 32 chunks of 64 KiB; iceoryx lets one publisher hold 8 at a
    // time, so five publishers holding every loan they get run the pool dry.
    std::vector<std::unique_ptr<engine::IpcPublisher>> publishers;
    std::size_t held = 0, exhausted = 0, too_many = 0;
    for (int p = 0; p < 5; ++p) {
      auto topic = engine::parse_topic("orthoflow/exhaust/t" + std::to_string(p));
      auto publisher = engine::IpcPublisher::create(
          *topic, {{engine::FRAME_TYPE_ID, engine::FRAME_VERSION}, 60000}, *pools);
      box.check(publisher.has_value(), "publisher " + std::to_string(p));
      if (!publisher) return;
      for (int k = 0; k < 12; ++k) {
        auto loan = (*publisher)->loan(60000);
        if (loan) {
          ++held;  // kept: returned when the publisher goes away
        } else {
          exhausted += loan.error().code == engine::IpcError::Code::POOL_EXHAUSTED ? 1U : 0U;
          too_many += loan.error().code == engine::IpcError::Code::TOO_MANY_LOANS ? 1U : 0U;
        }
      }
      publishers.push_back(std::move(*publisher));
    }
    box.check(held == 32,
              "every chunk of the 64 KiB pool loaned once (" + std::to_string(held) + ")");
    box.check(exhausted > 0, "POOL_EXHAUSTED once the pool is empty");
    box.check(too_many > 0, "TOO_MANY_LOANS past a publisher's limit");
    // Destroyed publishers give their chunks back when RouDi's discovery loop removes their ports
    // (asynchronously, every ~100 ms in 2.0.3): a new loan succeeds within a bounded wait.
    publishers.clear();
    auto topic = engine::parse_topic("orthoflow/exhaust/again");
    auto again = engine::IpcPublisher::create(
        *topic, {{engine::FRAME_TYPE_ID, engine::FRAME_VERSION}, 60000}, *pools);
    bool loaned = false;
    for (int attempt = 0; again && attempt < 60 && !loaned; ++attempt) {
      if (auto loan = (*again)->loan(60000)) {
        loaned = true;
        (*again)->release(*loan);
      } else {
        std::this_thread::sleep_for(50ms);
      }
    }
    box.check(loaned, "a loan succeeds within 3 s after the holders released theirs");
  });
}

}  // namespace
}  // namespace orthoflow::tests
