// Two machines on one box (issue 23): the bridge in one network namespace, a plain Cyclone DDS node
// in another, joined by a veth pair, discovery by unicast peers. On that link: 5 % packet loss in
// both directions (nftables `numgen random` drop rules: these kernels have no netem), then a
// partition (everything dropped for 3 s). Reliable object lists lose nothing and keep their order;
// best-effort frames count their losses; a teach sent during the loss is acknowledged; after the
// partition both sides go on without a restart. Needs root (ip netns, nft): skipped without it.
// Prints the numbers bench/RESULTS.md records (latency p50/p99, frames received, bridge CPU).
#include <gtest/gtest.h>

#include <unistd.h>

#include <csignal>
#include <cstdlib>
#include <string>
#include <thread>

#include "bridge/bridge_config.hpp"
#include "tests/ipc/roudi_sandbox.hpp"

namespace orthoflow::tests {
namespace {

using namespace std::chrono_literals;

const std::string SUBSCRIBER = ORTHOFLOW_BINARY_DIR "/tests/bridge/dds_plain_subscriber";
const std::string ORTHOFLOW = ORTHOFLOW_BINARY_DIR "/apps/orthoflow";

/// Two namespaces and a veth pair between them, removed again when it goes.
struct Link {
  std::string a, b;
  bool ok = false;
  Link() {
    const std::string id = std::to_string(::getpid());
    a = "ofdds_a" + id;
    b = "ofdds_b" + id;
    ok = sh("ip netns add " + a) && sh("ip netns add " + b) &&
         sh("ip link add va netns " + a + " type veth peer name vb netns " + b) &&
         sh("ip -n " + a + " addr add 10.77.0.1/24 dev va") &&
         sh("ip -n " + b + " addr add 10.77.0.2/24 dev vb") &&
         sh("ip -n " + a + " link set va up") && sh("ip -n " + b + " link set vb up") &&
         sh("ip -n " + a + " link set lo up") && sh("ip -n " + b + " link set lo up");
  }
  ~Link() {
    (void)sh("ip netns del " + a);
    (void)sh("ip netns del " + b);
  }
  static bool sh(const std::string& command) {
    return std::system((command + " >/dev/null 2>&1").c_str()) == 0;
  }
  /// Drops @p percent of the packets arriving in namespace @p ns (100: a partition).
  static bool drop(const std::string& ns, int percent) {
    const std::string nft = "ip netns exec " + ns + " nft ";
    (void)sh(nft + "delete table inet ofdds");
    if (percent == 0) return true;
    return sh(nft + "add table inet ofdds") &&
           sh(nft + "'add chain inet ofdds in { type filter hook input priority 0 ; }'") &&
           sh(nft + "add rule inet ofdds in " +
              (percent >= 100 ? std::string()
                              : "numgen random mod 100 lt " + std::to_string(percent) + " ") +
              "drop");
  }
};

// The rest of the line of @p text that starts with @p head (head included), or "".
std::string line_with(const std::string& text, const std::string& head) {
  const std::size_t at = text.find(head);
  if (at == std::string::npos) return "";
  return text.substr(at, text.find('\n', at) - at);
}

// The number right after @p head in @p text, or -1.
long number_after(const std::string& text, const std::string& head) {
  const std::size_t at = text.find(head);
  if (at == std::string::npos) return -1;
  return std::strtol(text.c_str() + at + head.size(), nullptr, 10);
}

TEST(DdsNetns, ReliableObjectsSurviveLossAndAPartitionAcrossTwoNamespaces) {
  if (::geteuid() != 0 || !Link::sh("command -v nft") || !Link::sh("command -v ip"))
    GTEST_SKIP() << "needs root, ip and nft (two network namespaces)";
  Link link;
  if (!link.ok) GTEST_SKIP() << "cannot make network namespaces and a veth pair here";
  const Outcome outcome = run_isolated(
      [&](Sandbox& box) {
        if (box.start_roudi(ORTHOFLOW_SOURCE_DIR "/config/roudi_frames.toml") < 0) return;
        const pid_t run = box.spawn_orthoflow("run", {"run", "--ipc-learning", "--publish-frames",
                                                      "--frames", "100000", "--rate", "10"});
        box.check(box.wait_for_output(run, "learning commands on", 60s), "the graph runs");
        // Reliable objects keep 200 lists: a 3 s partition at 10 Hz fits (docs/DDS.md, QoS).
        {
          std::FILE* f = std::fopen("/tmp/bridge.yaml", "w");
          std::fputs("qos:\n  objects: {reliability: reliable, depth: 200}\n", f);
          std::fclose(f);
        }
        const pid_t bridge = box.spawn_program("bridge", {"/usr/sbin/ip",
                                                          "netns",
                                                          "exec",
                                                          link.a,
                                                          ORTHOFLOW,
                                                          "bridge",
                                                          "dds",
                                                          "--config",
                                                          "/tmp/bridge.yaml",
                                                          "--interface",
                                                          "va",
                                                          "--allow-network",
                                                          "--accept-network-commands",
                                                          "--peer",
                                                          "10.77.0.2",
                                                          "--domain",
                                                          "212",
                                                          "--frames",
                                                          "--max-frame-hz",
                                                          "5",
                                                          "--seconds",
                                                          "120"});
        box.check(box.wait_for_output(bridge, "bridge dds: graph", 30s), "the bridge runs");
        bridge::BridgeConfig far;
        far.interface = "vb";
        far.allow_network = true;
        far.peers = {"10.77.0.1"};
        ::setenv("CYCLONEDDS_URI", bridge::cyclone_xml(far).c_str(), 1);
        const auto subscriber = [&](const std::string& name, const std::string& seconds,
                                    std::vector<std::string> extra) {
          std::vector<std::string> argv{"/usr/sbin/ip", "netns",     "exec", link.b,
                                        SUBSCRIBER,     "--domain",  "212",  "--points",
                                        "--all",        "--seconds", seconds};
          argv.insert(argv.end(), extra.begin(), extra.end());
          return box.spawn_program(name, argv);
        };
        // Clean link.
        const ProcResult clean = box.wait(subscriber("clean", "8", {}), 60s);
        box.check(clean.exit_code == 0, "objects and points across the link", clean);
        std::printf("clean link: %s\n", line_with(clean.out, "latency: ").c_str());
        std::printf("clean link: %s\n", line_with(clean.out, "received: ").c_str());
        std::fflush(stdout);
        // 5 % loss both ways, a teach during it, then a partition of 3 s, then the loss again.
        box.check(Link::drop(link.a, 5) && Link::drop(link.b, 5), "loss rules");
        const pid_t lossy = subscriber("lossy", "16", {"--teach", "cup"});
        std::this_thread::sleep_for(6s);
        box.check(Link::drop(link.a, 100) && Link::drop(link.b, 100), "partition");
        std::this_thread::sleep_for(3s);
        box.check(Link::drop(link.a, 5) && Link::drop(link.b, 5), "partition healed");
        const ProcResult loss = box.wait(lossy, 60s);
        (void)Link::drop(link.a, 0);
        (void)Link::drop(link.b, 0);
        std::printf("5%% loss + 3 s partition: %s\n", line_with(loss.out, "latency: ").c_str());
        std::printf("5%% loss + 3 s partition: %s\n", line_with(loss.out, "received: ").c_str());
        std::fflush(stdout);  // the scenario's process leaves with _exit
        box.check(loss.out.find(" (0 out of order, ") != std::string::npos, "objects keep order",
                  loss);
        box.check(loss.out.find("out of order, 0 missing)") != std::string::npos,
                  "reliable objects lose nothing", loss);
        box.check(loss.out.find("status 0 outcome 'learned'") != std::string::npos ||
                      loss.out.find("status 0 outcome 'stored'") != std::string::npos,
                  "the teach sent over the lossy link is acknowledged", loss);
        const long last = number_after(loss.out, "second 15: ");
        const long before = number_after(loss.out, "second 11: ");
        box.check(last > before, "after the partition the lists flow again", loss);
        ::kill(bridge, SIGTERM);
        const ProcResult b = box.wait(bridge, 30s);
        box.check(b.exit_code == 0, "the bridge kept running through it", b);
        std::printf("bridge: %s\n", line_with(b.out, "cpu: ").c_str());
        std::printf("bridge: %s\n", line_with(b.out, "bridge: objects ").c_str());
        std::fflush(stdout);
        ::kill(run, SIGTERM);
        (void)box.wait(run, 60s);
      },
      300s);
  if (outcome.skipped) GTEST_SKIP() << outcome.reason;
  EXPECT_EQ(outcome.failures, "");
}

}  // namespace
}  // namespace orthoflow::tests
