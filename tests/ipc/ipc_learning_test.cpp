// Teaching across processes: `orthoflow ui` serves the web view over a graph that `orthoflow run
// --ipc-learning` runs in another process (objects and status in, learning commands out, answers
// back over iceoryx; graphs/channels/learning_payloads.hpp), driven here by the CLI's thin client
// exactly as a person's page or a script would; and a process publishing malformed commands gets a
// refusal for each while the graph runs on. Own RouDi in a private mount namespace
// (roudi_sandbox.hpp).
#include <gtest/gtest.h>
#include <signal.h>

#include <chrono>
#include <fstream>
#include <map>
#include <span>
#include <sstream>
#include <string>
#include <thread>

#include "core/label_text.hpp"
#include "engine/ipc_pubsub.hpp"
#include "engine/ipc_runtime.hpp"
#include "graphs/channels/learning_payloads.hpp"
#include "tests/ipc/roudi_sandbox.hpp"

namespace orthoflow::tests {
namespace {

using namespace std::chrono_literals;

std::string file_text(const std::string& path) {
  std::ifstream in(path);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

// "ui: http://127.0.0.1:PORT/" in the ui's output.
std::string url_in(const std::string& out) {
  const std::size_t at = out.find("ui: http://");
  if (at == std::string::npos) return {};
  const std::size_t start = at + 4, end = out.find('/', start + 7);
  return end == std::string::npos ? std::string{} : out.substr(start, end - start);
}

ProcResult remote(Sandbox& box, const std::vector<std::string>& args) {
  return box.wait(box.spawn_orthoflow(args[0], args), 20s);
}

TEST(IpcLearning, StandaloneUiTeachesAsksAndUndoesOnAGraphInAnotherProcess) {
  const Outcome outcome = run_isolated(
      [](Sandbox& box) {
        if (box.start_roudi() < 0) return;
        const pid_t run = box.spawn_orthoflow("run", {"run", "--frames", "9000", "--rate", "30",
                                                      "--db", "/tmp/memory", "--ipc-learning"});
        box.check(box.wait_for_output(run, "learning commands on", 30s),
                  "the run says where it takes learning commands");
        const pid_t ui = box.spawn_orthoflow(
            "ui", {"ui", "--listen", "127.0.0.1:0", "--graph", "tabletop", "--seconds", "90"});
        box.check(box.wait_for_output(ui, "graph 'tabletop' connected", 30s),
                  "the ui sees the graph's status");
        const std::string url = url_in(file_text("/tmp/ui.out"));
        box.check(!url.empty(), "the ui prints its URL");
        if (url.empty()) return;
        bool tracked = false;  // the session's bottle is track 2 once the tracker has it
        for (int k = 0; k < 100 && !tracked; ++k) {
          const ProcResult state = remote(box, {"state", "--url", url});
          tracked = state.exit_code == 0 && state.out.find("  track 2  ") != std::string::npos;
          if (!tracked) std::this_thread::sleep_for(200ms);
        }
        box.check(tracked, "the page shows track 2");
        std::this_thread::sleep_for(300ms);  // a few frames on: described and key-viewed

        const ProcResult teach = remote(box, {"teach", "--url", url, "2", "flask"});
        box.check(teach.exit_code == 0 && teach.out.find("as \"flask\"") != std::string::npos &&
                      teach.out.find("(stored)") != std::string::npos,
                  "teach through the standalone ui is stored durably by the graph", teach);
        const ProcResult ask = remote(box, {"ask", "--url", url, "2"});
        // Track 2 is the session's bottle, which the scripted instructor teaches too: flask is
        // its nearest category or the runner-up.
        const std::size_t nearest = ask.out.find("nearest: ");
        box.check(ask.exit_code == 0 && nearest != std::string::npos &&
                      ask.out.find("flask", nearest) != std::string::npos,
                  "ask answers with the category just taught among the nearest", ask);
        bool listed = false;
        for (int k = 0; k < 20 && !listed; ++k) {  // the status comes five times a second
          const ProcResult state = remote(box, {"state", "--url", url});
          listed = state.exit_code == 0 && state.out.find("flask") != std::string::npos;
          if (!listed) std::this_thread::sleep_for(200ms);
        }
        box.check(listed, "the memory the page shows, from the graph's status, lists flask");
        const ProcResult forget = remote(box, {"forget", "--url", url, "nothere"});
        box.check(forget.exit_code == 30 && forget.err.find("unknown_label") != std::string::npos,
                  "forgetting an unknown category is refused with the graph's reason", forget);
        const ProcResult undo = remote(box, {"undo", "--url", url});
        // The session's scripted instructor teaches too, and undo takes back the newest lesson of
        // any sender: flask's, or one of the instructor's taught since.
        box.check(undo.exit_code == 0 && undo.out.find("took back ") != std::string::npos,
                  "undo takes the newest lesson back", undo);

        ::kill(run, SIGINT);
        const ProcResult r = box.wait(run, 20s);
        box.check(r.exit_code == 0, "the run stops on SIGINT", r);
        box.check(r.out.find("ipc learning: 4 commands (0 invalid, 0 unanswered), 4 answers") !=
                      std::string::npos,
                  "the run counts the four commands and their answers", r);
        box.check(box.wait_for_output(ui, "graph 'tabletop' lost", 10s),
                  "the ui says when the graph is gone");
        const auto before = std::chrono::steady_clock::now();
        const ProcResult late = remote(box, {"teach", "--url", url, "2", "flask"});
        const double took =
            std::chrono::duration<double>(std::chrono::steady_clock::now() - before).count();
        box.check(late.exit_code == 30 && late.err.find("timeout") != std::string::npos,
                  "with no graph a teach is refused as unanswered", late);
        box.check(took < 5.0,
                  "at once, not after the whole timeout (" + std::to_string(took) + " s)");
        ::kill(ui, SIGINT);
        const ProcResult u = box.wait(ui, 20s);
        box.check(u.exit_code == 0 && u.out.find("0 payloads rejected") != std::string::npos,
                  "the ui stops on SIGINT, having rejected nothing", u);
      },
      150s);
  if (outcome.skipped) GTEST_SKIP() << outcome.reason;
  EXPECT_EQ(outcome.failures, "");
}

template <class T>
std::span<const std::byte> bytes_of(const T& value) {
  return {reinterpret_cast<const std::byte*>(&value), sizeof value};
}

TEST(IpcLearning, MalformedCommandsFromAnotherProcessAreRefusedAndTheGraphRunsOn) {
  const Outcome outcome = run_isolated(
      [](Sandbox& box) {
        if (box.start_roudi() < 0) return;
        const pid_t run = box.spawn_orthoflow(
            "run", {"run", "--frames", "9000", "--rate", "30", "--ipc-learning"});
        box.check(box.wait_for_output(run, "learning commands on", 30s),
                  "the run takes learning commands");
        auto runtime = engine::init_ipc_runtime("malformed_sender");
        box.check(runtime.has_value(), "init_ipc_runtime");
        auto pools = engine::load_roudi_pools(ORTHOFLOW_SOURCE_DIR "/config/roudi_test.toml");
        auto commands = engine::IpcPublisher::create(
            *engine::parse_topic(graphs::learning_commands_topic("tabletop")),
            {{graphs::LEARNING_COMMAND_TYPE_ID, graphs::LEARNING_IPC_VERSION},
             sizeof(graphs::LearningCommandPayload)},
            *pools);
        auto acks = engine::IpcSubscriber::create(
            *engine::parse_topic(graphs::learning_acks_topic("tabletop")),
            {{graphs::LEARNING_ACK_TYPE_ID, graphs::LEARNING_IPC_VERSION},
             engine::IpcPolicy::QUEUE,
             16});
        box.check(commands.has_value() && acks.has_value(), "publisher and subscriber");
        if (!commands || !acks) return;
        for (int k = 0; k < 100 && !((*commands)->has_subscribers() && (*acks)->subscribed()); ++k)
          std::this_thread::sleep_for(50ms);

        constexpr std::uint64_t ME = 77;
        graphs::LearningCommand ask;
        ask.kind = graphs::LearningCommand::Kind::ASK;
        ask.track_id = 999;
        graphs::LearningCommandPayload p;
        (void)graphs::encode_command(ask, ME, 1, p);
        p.kind = 42;  // no such kind
        (void)(*commands)->publish_copy(bytes_of(p));
        graphs::LearningCommand teach;
        teach.kind = graphs::LearningCommand::Kind::TEACH;
        teach.track_id = 1;
        teach.label.assign("mug");
        (void)graphs::encode_command(teach, ME, 2, p);
        p.label.chars[1] = static_cast<char>(0xFF);  // not UTF-8
        (void)(*commands)->publish_copy(bytes_of(p));
        (void)graphs::encode_command(teach, ME, 3, p);
        p.payload_bytes = 64;  // passes the transport's header check, not the payload's
        (void)(*commands)->publish_copy(bytes_of(p));
        (void)graphs::encode_command(ask, ME, 4, p);  // valid, for a track that does not exist
        (void)(*commands)->publish_copy(bytes_of(p));

        std::map<std::uint64_t, graphs::RemoteAck> mine;
        std::uint64_t undecodable = 0;
        for (int k = 0; k < 250 && mine.size() < 3; ++k) {
          auto taken = (*acks)->take();
          if (taken && taken->has_value()) {
            auto d = graphs::decode_ack((*taken)->bytes());
            if (!d)
              ++undecodable;
            else if (d->client == ME)
              mine[d->request] = *d;
            continue;
          }
          std::this_thread::sleep_for(20ms);
        }
        box.check(undecodable == 0, "every ack decodes");
        box.check(mine.count(1) == 1 && mine[1].status == graphs::AckStatus::INVALID &&
                      mine[1].problem == 255,
                  "an unknown kind is refused as invalid");
        box.check(mine.count(2) == 1 && mine[2].status == graphs::AckStatus::INVALID &&
                      mine[2].problem == static_cast<std::uint32_t>(core::LabelProblem::NOT_UTF8),
                  "a label that is not UTF-8 is refused by the label rule");
        box.check(mine.count(4) == 1 && mine[4].status == graphs::AckStatus::ACKNOWLEDGED &&
                      mine[4].ack.outcome == graphs::LearningAck::Outcome::NO_SUCH_TRACK,
                  "a valid ask for a missing track is answered no_such_track");
        box.check(mine.count(3) == 0, "a payload too broken to trust names no request");

        ::kill(run, SIGINT);
        const ProcResult r = box.wait(run, 20s);
        box.check(r.exit_code == 0, "the run ran on and stops on SIGINT", r);
        box.check(r.out.find("ipc learning: 4 commands (3 invalid, 0 unanswered), 4 answers") !=
                      std::string::npos,
                  "the run counts the three refusals", r);
      },
      120s);
  if (outcome.skipped) GTEST_SKIP() << outcome.reason;
  EXPECT_EQ(outcome.failures, "");
}

}  // namespace
}  // namespace orthoflow::tests
