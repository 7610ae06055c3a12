#include "apps/run_ui.hpp"

#include <algorithm>
#include <iostream>

#include "apps/commands.hpp"
#include "ui/graph_backend.hpp"
#include "ui/ui_server.hpp"

namespace orthoflow::apps {

namespace {

// Members in this order: the server (which calls the backend) goes first.
class RunningUi final : public RunUi {
 public:
  std::unique_ptr<ui::GraphBackend> backend;
  std::unique_ptr<ui::UiServer> server;
  ~RunningUi() override {
    server.reset();
    backend.reset();
  }
};

[[noreturn]] void fail(const std::string& message, int code) {
  std::cerr << "run: --ui: " << message << "\n";
  throw CLI::RuntimeError(code);
}

}  // namespace

std::string check_ui_listen(const std::string& value) {
  ui::UiServerConfig config;
  auto parsed = ui::parse_listen(value, config);
  return parsed ? std::string{} : parsed.error();
}

std::unique_ptr<RunUi> start_run_ui(const std::string& listen, const std::string& token_file,
                                    graphs::LearningService& learning, graphs::ObjectsHub& hub,
                                    const engine::GraphStats& stats, std::int64_t period_ns) {
  ui::UiServerConfig config;
  if (auto parsed = ui::parse_listen(listen, config); !parsed) fail(parsed.error(), EXIT_USAGE);
  if (!token_file.empty()) {
    auto token_result = ui::read_token_file(token_file);
    if (!token_result) fail(token_result.error(), EXIT_USAGE);
    config.token = *token_result;
  }
  const double frame_hz = period_ns > 0 ? 1e9 / static_cast<double>(period_ns) : 30.0;
  config.max_stream_hz = std::min(30.0, frame_hz);
  auto running = std::make_unique<RunningUi>();
  auto backend_result = ui::GraphBackend::open(learning, hub);
  if (!backend_result) fail(backend_result.error(), EXIT_FAILURE_GENERIC);
  running->backend = std::move(*backend_result);
  running->backend->set_telemetry(&stats);
  auto server_result = ui::UiServer::start(config, *running->backend);
  if (!server_result) fail(server_result.error(), EXIT_FAILURE_GENERIC);
  running->server = std::move(*server_result);
  std::cout << "ui: " << running->server->url() << "\n";
  if (!running->server->token().empty()) {
    std::cout << "ui: bearer token " << running->server->token()
              << " (Authorization: Bearer <token>, or ?token=<token> in the page's URL)\n";
  }
  std::cout.flush();
  return running;
}

}  // namespace orthoflow::apps
