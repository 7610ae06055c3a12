// `orthoflow teach|correct|ask|forget|undo|state --url http://HOST:PORT ...`: a thin client of a
// running orthoflow's teaching API (ui/, docs/ui-api.openapi.yaml), for scripts and bridges. The
// label is checked here with the same rule as the server's, so a bad one fails before any request.
#include <nlohmann/json.hpp>

#include <iostream>
#include <memory>
#include <string>

#include "apps/commands.hpp"
#include "apps/option_checks.hpp"
#include "core/label_text.hpp"
#include "ui/server_config.hpp"
#include "ui/ui_client.hpp"

namespace orthoflow::apps {
namespace {

using Json = nlohmann::json;

struct RemoteOptions {
  std::string url;
  std::string token_file;
  double timeout_s = 5.0;
  bool json = false;
  std::uint32_t track = 0;
  std::string label;
};

[[noreturn]] void fail(const std::string& command, const std::string& message, int code) {
  std::cerr << command << ": " << message << "\n";
  throw CLI::RuntimeError(code);
}

ui::ClientTarget target_of(const std::string& command, const RemoteOptions& o) {
  auto target = ui::parse_ui_url(o.url);
  if (!target) fail(command, target.error(), EXIT_USAGE);
  if (!o.token_file.empty()) {
    auto token = ui::read_token_file(o.token_file);
    if (!token) fail(command, token.error(), EXIT_USAGE);
    target->token = *token;
  }
  if (o.timeout_s <= 0.0 || o.timeout_s > 600.0)
    fail(command, "--timeout must be in (0, 600] seconds", EXIT_USAGE);
  target->timeout_ms = static_cast<int>(o.timeout_s * 1000.0);
  return *target;
}

std::string text_of(const Json& v) {
  return v.is_string() ? v.get<std::string>() : v.is_null() ? "Unknown" : v.dump();
}

// One line a person reads for an acknowledged action.
std::string describe(const std::string& command, const Json& doc) {
  const std::string outcome = doc.value("outcome", std::string("?"));
  const std::string views = std::to_string(doc.value("views", 0));
  if (command == "ask") {
    std::string line = "track " + std::to_string(doc.value("track", 0)) + ": " +
                       text_of(doc.value("answer", Json())) + " (score " +
                       text_of(doc.value("score", Json())) + ")";
    const Json nearest = doc.value("nearest", Json::array());
    if (!nearest.empty()) {
      line += "; nearest:";
      for (const Json& n : nearest) {
        line += " " + text_of(n.value("label", Json()));
        if (n.contains("score") && !n["score"].is_null()) line += " " + text_of(n["score"]);
      }
    }
    return line;
  }
  if (command == "undo") {
    return "took back " + views + " view(s) of \"" + text_of(doc.value("label", Json())) + "\" (" +
           outcome + ")";
  }
  if (command == "forget")
    return "forgot \"" + text_of(doc.value("label", Json())) + "\" (" + outcome + ")";
  return command + " track " + std::to_string(doc.value("track", 0)) + " as \"" +
         text_of(doc.value("label", Json())) + "\": " + views + " view(s) (" + outcome + ")";
}

// The state document as a short table: objects, then the memory.
void print_state(const Json& doc) {
  std::cout << "frame " << doc.value("frame", 0) << ", " << doc["objects"].size() << " object(s), "
            << doc["memory"].size() << " categor" << (doc["memory"].size() == 1 ? "y" : "ies")
            << (doc.value("durable", false) ? " (durable)" : " (in memory)") << "\n";
  for (const Json& o : doc["objects"]) {
    if (o.value("fragment", false)) continue;
    std::cout << "  track " << o.value("track", 0) << "  " << text_of(o.value("label", Json()))
              << "  score " << text_of(o.value("score", Json())) << "\n";
  }
  for (const Json& m : doc["memory"]) {
    std::cout << "  category \"" << text_of(m.value("label", Json())) << "\"  "
              << m.value("views", 0) << " view(s)\n";
  }
}

void run_remote(const std::string& command, const RemoteOptions& o) {
  const ui::ClientTarget target = target_of(command, o);
  Json body = Json::object();
  if (command == "teach" || command == "correct" || command == "ask") body["track"] = o.track;
  if (command == "teach" || command == "correct" || command == "forget") {
    if (const auto problem = core::check_label(o.label); problem != core::LabelProblem::NONE)
      fail(command, std::string(core::to_string(problem)), EXIT_USAGE);
    body["label"] = o.label;
  }
  const bool state = command == "state";
  auto reply = state ? ui::send_ui_request(target, "GET", "/api/state", "")
                     : ui::send_ui_request(target, "POST", "/api/" + command, body.dump());
  if (!reply) fail(command, reply.error(), EXIT_UNREACHABLE);
  const Json doc = Json::parse(reply->body, nullptr, false);
  if (doc.is_discarded() || !doc.is_object())
    fail(command, "HTTP " + std::to_string(reply->status) + " with a body that is not JSON",
         EXIT_REFUSED);
  if (reply->status != 200) {
    if (o.json) std::cout << doc.dump() << "\n";
    // "refused (HTTP 404, unknown_label): no category of that name in the memory": the outcome
    // for scripts, the error for people.
    const std::string outcome = doc.contains("outcome") ? ", " + text_of(doc["outcome"]) : "";
    const std::string why = doc.contains("error") ? text_of(doc["error"]) : doc.dump();
    fail(command, "refused (HTTP " + std::to_string(reply->status) + outcome + "): " + why,
         EXIT_REFUSED);
  }
  if (o.json) {
    std::cout << doc.dump() << "\n";
  } else if (state) {
    print_state(doc);
  } else {
    std::cout << describe(command, doc) << "\n";
  }
}

void add_common(CLI::App& sub, RemoteOptions& o) {
  sub.add_option("--url", o.url, "the running orthoflow's UI, http://HOST:PORT (run --ui)")
      ->required()
      ->envname("ORTHOFLOW_URL");
  sub.add_option("--token-file", o.token_file,
                 "file holding the bearer token (needed when the UI listens beyond loopback)")
      ->envname("ORTHOFLOW_TOKEN_FILE");
  sub.add_option("--timeout", o.timeout_s, "seconds to wait for the answer (default 5)");
  sub.add_flag("--json", o.json, "print the server's JSON answer as it came");
}

}  // namespace

void add_remote_commands(CLI::App& app) {
  auto o = std::make_shared<RemoteOptions>();
  struct Spec {
    const char* name;
    const char* help;
    bool track;
    bool label;
  };
  const Spec specs[] = {
      {"teach", "teach a running robot: track TRACK is a LABEL (its key views are stored)", true,
       true},
      {"correct", "correct a running robot's answer for TRACK: it is a LABEL", true, true},
      {"ask", "ask a running robot what TRACK is (answer and nearest categories)", true, false},
      {"forget", "make a running robot forget the category LABEL", false, true},
      {"undo", "take back a running robot's last teach or correct", false, false},
      {"state", "what a running robot sees and knows: objects and memory", false, false},
  };
  for (const Spec& s : specs) {
    CLI::App* sub = app.add_subcommand(s.name, s.help);
    add_common(*sub, *o);
    if (s.track) {
      sub->add_option("TRACK", o->track, "track id, as the page, `state` or the JSON lines show")
          ->required()
          ->check(CLI::Range(1U, 4294967295U));
    }
    if (s.label)
      sub->add_option("LABEL", o->label, "category label")->required()->transform(composed_label());
    const std::string name = s.name;
    sub->callback([o, name] { run_remote(name, *o); });
  }
}

}  // namespace orthoflow::apps
