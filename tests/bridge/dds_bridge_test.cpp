// The DDS bridge across processes (issue 23): a graph (`orthoflow run --ipc-learning
// --publish-frames`), the bridge (`orthoflow bridge dds --frames`) and a plain Cyclone DDS node
// (tests/bridge/plain_subscriber.c: the C API and the IDL's generated types, no orthoflow code),
// each its own process, on loopback. Objects and a frame stream reach the plain node; its teach
// reaches the learner and is acknowledged; malformed commands, an unknown track and a graph that is
// gone are answered, counted, and the bridge keeps running; the graph restarted, objects flow
// again.
#include <gtest/gtest.h>

#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <thread>

#include "bridge/bridge_config.hpp"
#include "tests/ipc/roudi_sandbox.hpp"

namespace orthoflow::tests {
namespace {

using namespace std::chrono_literals;

constexpr const char* DOMAIN_ID = "211";  // no other test uses it
const std::string SUBSCRIBER = ORTHOFLOW_BINARY_DIR "/tests/bridge/dds_plain_subscriber";
const std::string ARM_STOPPER = ORTHOFLOW_BINARY_DIR "/tests/bridge/dds_plain_arm_stop";

ProcResult plain(Sandbox& box, const std::string& name, std::vector<std::string> args) {
  std::vector<std::string> argv{SUBSCRIBER, "--domain", DOMAIN_ID};
  argv.insert(argv.end(), args.begin(), args.end());
  return box.wait(box.spawn_program(name, argv), 60s);
}

bool has(const ProcResult& p, const std::string& text) {
  return p.out.find(text) != std::string::npos;
}

pid_t start_graph(Sandbox& box, const std::string& name) {
  const pid_t run = box.spawn_orthoflow(
      name, {"run", "--ipc-learning", "--publish-frames", "--frames", "100000", "--rate", "10"});
  box.check(box.wait_for_output(run, "learning commands on", 60s), name + ": the graph runs");
  return run;
}

TEST(DdsBridge, ObjectsFramesAndLessonsCrossToAPlainDdsNodeAndBack) {
  const Outcome outcome = run_isolated(
      [](Sandbox& box) {
        if (box.start_roudi(ORTHOFLOW_SOURCE_DIR "/config/roudi_frames.toml") < 0) return;
        // The plain node finds the bridge as the bridge's own loopback configuration says.
        // ... with a socket receive buffer that holds a whole 4.9 MB cloud (docs/DDS.md: the kernel
        // caps the request at rmem_max; under ASan a slow reader lost every cloud without it).
        std::string xml = bridge::cyclone_xml(bridge::BridgeConfig{});
        xml.replace(xml.find("</General>"), 10,
                    "</General><Internal><SocketReceiveBufferSize max=\"32MB\"/></Internal>");
        ::setenv("CYCLONEDDS_URI", xml.c_str(), 1);
        pid_t run = start_graph(box, "run");
        const pid_t bridge = box.spawn_orthoflow(
            "bridge", {"bridge", "dds", "--frames", "--max-frame-hz", "2", "--domain", DOMAIN_ID,
                       "--seconds", "200", "--telemetry-json", "/tmp/bridge.json"});
        box.check(box.wait_for_output(bridge, "rt/orthoflow/tabletop/objects", 30s),
                  "the bridge names its topics");

        const ProcResult taught = plain(box, "teach", {"--points", "--teach", "mug"});
        box.check(taught.exit_code == 0, "objects, points and an ack reach the plain node", taught);
        box.check(has(taught, "frame_id camera_depth_optical_frame"), "objects' frame", taught);
        // The simulated camera knows its pose: the table verdict crosses with its "up".
        box.check(has(taught, "table true (accepted, gravity sensor)"), "the table verdict",
                  taught);
        box.check(has(taught, "points: 640x480, 4 fields (x), point_step 16, row_step 10240"),
                  "an organized PointCloud2 as ROS drivers publish it", taught);
        box.check(
            has(taught, "status 0 outcome 'learned'") || has(taught, "status 0 outcome 'stored'"),
            "the learner learned the teach and said so", taught);
        box.check(!has(taught, "bad quaternion"), "unit quaternions", taught);

        const ProcResult asked = plain(box, "ask", {"--raw-command", "3", ""});
        box.check(has(asked, "outcome 'answered'"), "an ask is answered", asked);
        const ProcResult empty = plain(box, "empty", {"--raw-command", "0", ""});
        box.check(has(empty, "status 2 outcome '' problem 'label is empty'"),
                  "an empty label is refused before the graph", empty);
        const ProcResult kind = plain(box, "kind", {"--raw-command", "9", "mug"});
        box.check(has(kind, "status 2"), "an unknown kind is refused", kind);
        const ProcResult nobody =
            plain(box, "nobody", {"--raw-command", "0", "mug", "--track", "4000000"});
        box.check(has(nobody, "status 0 outcome 'no_such_track'"),
                  "a command for an unknown track gets the learner's answer", nobody);

        // The graph goes away: commands are answered, the bridge stays.
        ::kill(run, SIGTERM);
        box.check(box.wait(run, 60s).exit_code == 0, "the graph stops");
        const ProcResult gone =
            plain(box, "gone", {"--raw-command", "3", "", "--objects-min", "0", "--seconds", "3"});
        box.check(!has(gone, "status 0"), "no learner answers while the graph is gone", gone);
        run = start_graph(box, "run2");
        const ProcResult again = plain(box, "again", {"--objects-min", "5"});
        box.check(again.exit_code == 0, "objects flow again after the graph restarted", again);

        ::kill(bridge, SIGTERM);
        const ProcResult b = box.wait(bridge, 30s);
        box.check(b.exit_code == 0, "the bridge ran through it all and stops on SIGTERM", b);
        box.check(has(b, "invalid 2"), "the two refused commands are counted", b);
        box.check(has(b, "write errors 0"), "no DDS write failed", b);
        ::kill(run, SIGTERM);
        (void)box.wait(run, 60s);
      },
      300s);
  if (outcome.skipped) GTEST_SKIP() << outcome.reason;
  EXPECT_EQ(outcome.failures, "");
}

// The arm's stop from DDS (docs/SAFETY.md section 4): a plain DDS node (plain_arm_stop.c) writes
// an ArmStop; with no process holding an arm, the bridge answers at once that none listens; with
// `orthoflow arm move --sim` holding a moving arm, the bridge passes the stop over iceoryx, the
// holder halts the arm in place and latches the stop, and the ArmStopAck says so, with the holder
// and the time from the request to the halt.
TEST(DdsBridge, AStopFromAPlainDdsNodeHaltsTheArmsHolderAndIsLatched) {
  const Outcome outcome = run_isolated(
      [](Sandbox& box) {
        if (box.start_roudi() < 0) return;
        const std::string xml = bridge::cyclone_xml(bridge::BridgeConfig{});
        ::setenv("CYCLONEDDS_URI", xml.c_str(), 1);
        const pid_t bridge = box.spawn_orthoflow(
            "bridge", {"bridge", "dds", "--domain", DOMAIN_ID, "--seconds", "120"});
        box.check(box.wait_for_output(bridge, "rt/orthoflow/tabletop/objects", 30s),
                  "the bridge names its topics");
        const auto stop = [&](const std::string& name, const std::string& reason) {
          return box.wait(box.spawn_program(name, {ARM_STOPPER, "--domain", DOMAIN_ID, "--reason",
                                                   reason, "--seconds", "20"}),
                          30s);
        };
        const ProcResult nobody = stop("nobody", "nobody home");
        box.check(nobody.exit_code == 0 && has(nobody, "stopped 0") &&
                      has(nobody, "no process holding an arm listens for stops"),
                  "with no holder the bridge says so at once", nobody);

        const pid_t move = box.spawn_orthoflow("move", {"arm", "move", "--sim", "--speed", "0.3",
                                                        "--joints", "355,167.5,57.5,240,82.5,75"});
        std::this_thread::sleep_for(1500ms);
        const ProcResult stopped = stop("stop", "dds test");
        box.check(stopped.exit_code == 0 && has(stopped, "stopped 1 was_moving 1") &&
                      has(stopped, "holder_pid " + std::to_string(move) + " ") &&
                      has(stopped, "holder 'orthoflow arm move'"),
                  "the holder halted the moving arm and said so over DDS", stopped);
        double halt_ms = 1e9, round_trip_ms = 1e9;
        const std::size_t at = stopped.out.find("request_to_halt_ms");
        if (at != std::string::npos)
          (void)std::sscanf(stopped.out.c_str() + at, "request_to_halt_ms %lf round_trip_ms %lf",
                            &halt_ms, &round_trip_ms);
        box.check(halt_ms < 100.0, "halted within 100 ms of the bridge's request", stopped);
        std::printf("DDS stop: request to halt %.3f ms, DDS round trip %.3f ms\n", halt_ms,
                    round_trip_ms);
        const ProcResult m = box.wait(move, 20s);
        box.check(m.exit_code == 1 && m.err.find("dds test") != std::string::npos &&
                      m.err.find("latched") != std::string::npos,
                  "the move ends: stopped from DDS, latched", m);
        const ProcResult again = box.wait(
            box.spawn_orthoflow("again",
                                {"arm", "move", "--sim", "--joints", "280,167.5,57.5,240,82.5,75"}),
            20s);
        box.check(again.exit_code == 1 && again.err.find("latched") != std::string::npos,
                  "the next holder refuses to move while latched", again);
        ::kill(bridge, SIGTERM);
        const ProcResult b = box.wait(bridge, 30s);
        box.check(b.exit_code == 0, "the bridge stops on SIGTERM", b);
      },
      120s);
  if (outcome.skipped) GTEST_SKIP() << outcome.reason;
  EXPECT_EQ(outcome.failures, "");
}

}  // namespace
}  // namespace orthoflow::tests
