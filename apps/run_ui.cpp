#include "apps/run_ui.hpp"

#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <csignal>
#include <iostream>
#include <thread>

#include "apps/commands.hpp"
#include "apps/graph_run.hpp"
#include "engine/ipc_runtime.hpp"
#include "graphs/services/learning_ipc_bridge.hpp"
#include "ui/graph_backend.hpp"
#include "ui/ipc_backend.hpp"
#include "ui/ipc_task_link.hpp"
#include "ui/ui_server.hpp"

namespace orthoflow::apps {

namespace {

// Members in this order: the server (which calls the backend) goes first.
class RunningUi final : public RunUi {
 public:
  std::unique_ptr<ui::IpcTaskLink> tasks;
  std::unique_ptr<ui::GraphBackend> backend;
  std::unique_ptr<ui::UiServer> server;
  ~RunningUi() override {
    server.reset();
    backend.reset();
    tasks.reset();
  }
};

// The page's task buttons: over iceoryx to `orthoflow task run`, when this process has the
// runtime (null, with a line saying why, when the link cannot open).
std::unique_ptr<ui::IpcTaskLink> open_task_link(const std::string& graph) {
  auto link = ui::IpcTaskLink::open(graph);
  if (!link) {
    std::cout << "ui: no task control (" << link.error() << ")\n";
    return nullptr;
  }
  return std::move(*link);
}

[[noreturn]] void fail(const std::string& message, int code, const char* who = "run: --ui") {
  std::cerr << who << ": " << message << "\n";
  throw CLI::RuntimeError(code);
}

// Starts the server for @p backend and prints its URL (and the token when one is needed).
std::unique_ptr<ui::UiServer> start_server(const std::string& listen, const std::string& token_file,
                                           double max_stream_hz, ui::UiBackend& backend,
                                           const char* who) {
  ui::UiServerConfig config;
  if (auto parsed = ui::parse_listen(listen, config); !parsed)
    fail(parsed.error(), EXIT_USAGE, who);
  if (!token_file.empty()) {
    auto token_result = ui::read_token_file(token_file);
    if (!token_result) fail(token_result.error(), EXIT_USAGE, who);
    config.token = *token_result;
  }
  config.max_stream_hz = max_stream_hz;
  auto server_result = ui::UiServer::start(config, backend);
  if (!server_result) fail(server_result.error(), EXIT_FAILURE_GENERIC, who);
  auto server = std::move(*server_result);
  std::cout << "ui: " << server->url() << "\n";
  // Where the token is, never the token: this output goes to the journal under the image's unit.
  if (!server->token().empty()) {
    std::string where = token_file;
    if (where.empty()) {  // generated: beyond loopback without --ui-token-file
      auto written = ui::write_private_token(server->token());
      if (!written) fail(written.error(), EXIT_FAILURE_GENERIC, who);
      where = *written + " (generated; readable by this user only)";
    }
    std::cout
        << "ui: bearer token: the first line of " << where
        << " (send Authorization: Bearer <token>, or open the page once with ?token=<token>)\n";
  }
  std::cout.flush();
  return server;
}

std::atomic<bool> g_ui_stop{false};
extern "C" void on_ui_signal(int /*signal*/) { g_ui_stop.store(true, std::memory_order_relaxed); }

struct UiOptions {
  std::string graph = "tabletop";
  std::string listen;
  std::string token_file;
  double seconds = 0;  // 0: until a signal
};

// `orthoflow ui`: the web view in a process of its own, over a graph that runs with
// --ipc-learning. Ends on SIGINT / SIGTERM (exit 0), after --seconds, or when RouDi is lost (22).
void run_standalone_ui(const UiOptions& o) {
  constexpr const char* WHO = "ui";
  auto init = engine::init_ipc_runtime("orthoflow_ui_" + std::to_string(::getpid()));
  if (!init) {
    fail(to_string(init.error()),
         init.error().code == engine::IpcError::Code::ROUDI_UNREACHABLE ? EXIT_NO_ROUDI
                                                                        : EXIT_FAILURE_GENERIC,
         WHO);
  }
  auto backend = ui::IpcBackend::open(o.graph);
  if (!backend) fail(backend.error(), EXIT_FAILURE_GENERIC, WHO);
  std::unique_ptr<ui::IpcTaskLink> tasks = open_task_link(o.graph);
  (*backend)->set_task_link(tasks.get());
  g_ui_stop.store(false);
  auto previous_int = std::signal(SIGINT, on_ui_signal);
  auto previous_term = std::signal(SIGTERM, on_ui_signal);
  auto server = start_server(o.listen, o.token_file, 30.0, **backend, WHO);
  std::cout << "ui: graph '" << o.graph << "' over iceoryx (start it with orthoflow run "
            << "--ipc-learning)\n";
  std::cout.flush();
  const auto start = std::chrono::steady_clock::now();
  bool said_connected = false;
  while (!g_ui_stop.load() && !engine::ipc_roudi_lost() && engine::probe_roudi()) {
    if (o.seconds > 0 &&
        std::chrono::steady_clock::now() - start > std::chrono::duration<double>(o.seconds))
      break;
    if ((*backend)->connected() != said_connected) {
      said_connected = !said_connected;
      std::cout << "ui: graph '" << o.graph << "' " << (said_connected ? "connected" : "lost")
                << "\n";
      std::cout.flush();
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
  server.reset();
  const bool lost = engine::ipc_roudi_lost() || !engine::probe_roudi();
  const ui::IpcBackendCounters& c = (*backend)->counters();
  std::cout << "ui: " << c.object_lists.load() << " object lists, " << c.statuses.load()
            << " statuses, " << c.acks.load() << " acknowledgements taken, " << c.rejected.load()
            << " payloads rejected\n";
  backend->reset();
  tasks.reset();
  std::signal(SIGINT, previous_int);
  std::signal(SIGTERM, previous_term);
  if (lost) fail(roudi_lost_text("serving the web view"), EXIT_ROUDI_LOST, WHO);
}

}  // namespace

std::string check_ui_listen(const std::string& value) {
  ui::UiServerConfig config;
  auto parsed = ui::parse_listen(value, config);
  return parsed ? std::string{} : parsed.error();
}

std::unique_ptr<RunUi> start_run_ui(const std::string& listen, const std::string& token_file,
                                    graphs::LearningService& learning, graphs::ObjectsHub& hub,
                                    const engine::GraphStats& stats, std::int64_t period_ns,
                                    const std::string& graph) {
  const double frame_hz = period_ns > 0 ? 1e9 / static_cast<double>(period_ns) : 30.0;
  auto running = std::make_unique<RunningUi>();
  auto backend_result = ui::GraphBackend::open(learning, hub);
  if (!backend_result) fail(backend_result.error(), EXIT_FAILURE_GENERIC);
  running->backend = std::move(*backend_result);
  // Task commands go over iceoryx: only when the graph publishes (--ipc-learning,
  // --publish-objects), as `orthoflow task run` needs its objects anyway.
  if (engine::ipc_runtime_ready()) {
    running->tasks = open_task_link(graph);
    running->backend->set_task_link(running->tasks.get());
  }
  running->backend->set_telemetry(&stats);
  running->server =
      start_server(listen, token_file, std::min(30.0, frame_hz), *running->backend, "run: --ui");
  return running;
}

void add_ui_command(CLI::App& app) {
  auto o = std::make_shared<UiOptions>();
  auto* cmd = app.add_subcommand(
      "ui",
      "Serve the live web view and its JSON API for a graph running in another process (orthoflow "
      "run --ipc-learning) over iceoryx (needs RouDi)");
  cmd->add_option("--listen", o->listen,
                  "[ADDR:]PORT to serve on (default address 127.0.0.1; another address needs the "
                  "bearer token printed at start; ui/README.md)")
      ->required()
      ->check(check_ui_listen);
  cmd->add_option("--graph", o->graph, "the graph's name (its topics orthoflow/<graph>/...)")
      ->check([](const std::string& v) {
        auto topics = graphs::graph_topics(v);
        return topics ? std::string{} : topics.error();
      });
  cmd->add_option("--token-file", o->token_file,
                  "read the bearer token from FILE instead of generating one");
  cmd->add_option("--seconds", o->seconds, "stop after S seconds (default: at SIGINT / SIGTERM)")
      ->check(CLI::NonNegativeNumber);
  cmd->callback([o] { run_standalone_ui(*o); });
}

}  // namespace orthoflow::apps
