// `orthoflow demo clear-table|serve-a-meal`: the whole closed loop of issue 21 on the simulators
// (graphs/sessions/table_task_session.hpp): a seeded table, a person teaching every object's
// category, the task planned from the learner's labels, and the simulated JACO moving each object
// under the execution manager while the tabletop graph watches. Prints per move the label, the
// grasp, every operator's time and the outcome; --scenes N runs N seeds and sums them up;
// --pictures DIR writes the world from above as PNG frames; --json for machines.
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "apps/commands.hpp"
#include "apps/demo_picture.hpp"
#include "graphs/sessions/table_task_session.hpp"
#include "manipulation/robot_frames.hpp"

namespace orthoflow::apps {
namespace {

struct DemoArgs {
  std::string task;
  std::vector<std::string> categories;  // serve-a-meal: what to bring
  std::vector<std::string> keep{"plate"};
  std::uint64_t seed = 1;
  std::uint32_t objects = 5;
  std::uint32_t scenes = 1;
  std::string event = "none";
  std::string event_phase = "approach";
  std::string pictures;
  std::uint32_t picture_every = 5;
  std::string robot_frames;
  bool json = false;
};

nlohmann::json to_json(const graphs::TableTaskReport& r) {
  nlohmann::json moves = nlohmann::json::array();
  for (const graphs::MoveReport& m : r.moves) {
    nlohmann::json ops = nlohmann::json::array();
    for (const graphs::OperatorTime& o : m.operators)
      ops.push_back({{"phase", o.phase}, {"seconds", o.seconds}});
    moves.push_back({{"track", m.track},
                     {"label", m.label},
                     {"truth", m.truth},
                     {"to_m", {m.to.x(), m.to.y()}},
                     {"grasp", m.grasp},
                     {"operators", ops},
                     {"done", m.done},
                     {"arrived", m.arrived},
                     {"held", m.held},
                     {"error_m", m.error_m},
                     {"max_tilt_deg", m.max_tilt_deg},
                     {"spilled", m.spilled},
                     {"dropped", m.dropped},
                     {"failure", m.failure},
                     {"seconds", m.seconds},
                     {"decisions", m.decisions},
                     {"attempt", m.attempt},
                     {"retry_of", m.attempt > 1 ? nlohmann::json(m.retry_of) : nlohmann::json()}});
  }
  nlohmann::json stays = nlohmann::json::array();
  for (const graphs::StayReport& s : r.stays)
    stays.push_back(
        {{"track", s.track}, {"label", s.label}, {"truth", s.truth}, {"reason", s.reason}});
  return {{"task", r.task},
          {"seed", r.seed},
          {"scene", r.scene},
          {"taught", r.taught},
          {"perceived", r.perceived},
          {"recognised", r.recognised},
          {"refused", r.refused},
          {"stopped", r.stopped},
          {"moves", moves},
          {"stays", stays},
          {"arrived", r.arrived()},
          {"frames", r.frames},
          {"seconds", r.seconds},
          {"body_dropped", r.body_dropped},
          {"fallen", r.fallen},
          {"spills", r.spills},
          {"drops", r.drops},
          {"calibrated", r.calibrated},
          {"hand_eye_error_mm", r.hand_eye_error_mm},
          {"hand_eye_error_deg", r.hand_eye_error_deg}};
}

void print(const graphs::TableTaskReport& r) {
  std::printf(
      "%s, seed %llu: %zu objects on the table, %zu taught, %zu of %zu perceived "
      "recognised right\n",
      r.task.c_str(), static_cast<unsigned long long>(r.seed), r.scene.size(), r.taught,
      r.recognised, r.perceived);
  if (r.calibrated)
    std::printf(
        "  the robot's calibration is %.1f mm and %.2f degrees from the simulator's truth\n",
        r.hand_eye_error_mm, r.hand_eye_error_deg);
  if (!r.refused.empty()) {
    std::printf("  refused: %s\n", r.refused.c_str());
    return;
  }
  int n = 0;
  for (const graphs::MoveReport& m : r.moves) {
    std::printf("  %d.%s track %u %s (truth %s) to [%.2f, %.2f]: %s grasp, %s in %.1f s%s%s\n", ++n,
                m.attempt > 1 ? " retry:" : "", m.track, m.label.c_str(),
                m.truth.empty() ? "-" : m.truth.c_str(), m.to.x(), m.to.y(),
                m.grasp.empty() ? "no" : m.grasp.c_str(),
                m.arrived ? "placed"
                          : (m.done ? (m.held ? "done, not at the spot" : "done, missed the object")
                                    : "FAILED"),
                m.seconds, m.failure.empty() ? "" : ": ", m.failure.c_str());
    if (m.held)
      std::printf("     carried tilted at most %.1f degrees%s%s\n", m.max_tilt_deg,
                  m.spilled ? ", SPILLED" : "", m.dropped ? ", SLIPPED OUT" : "");
    std::string ops;
    for (const graphs::OperatorTime& o : m.operators) {
      char one[48];
      std::snprintf(one, sizeof one, "%s%s %.1f", ops.empty() ? "" : ", ", o.phase.c_str(),
                    o.seconds);
      ops += one;
    }
    if (!ops.empty()) std::printf("     operators (s): %s\n", ops.c_str());
  }
  for (const graphs::StayReport& s : r.stays)
    std::printf("  stays: track %u %s (truth %s): %s\n", s.track,
                s.label.empty() ? "Unknown" : s.label.c_str(),
                s.truth.empty() ? "-" : s.truth.c_str(), s.reason.c_str());
  if (!r.stopped.empty()) std::printf("  stopped: %s\n", r.stopped.c_str());
  std::printf(
      "  %zu of %zu objects placed (%zu retried); %.1f s simulated, %llu frames, %llu dropped by "
      "the body filter, %zu fell off the table, %zu spilled, %zu slipped out of the hand\n",
      r.arrived(), r.first_moves(), r.moves.size() - r.first_moves(), r.seconds,
      static_cast<unsigned long long>(r.frames), static_cast<unsigned long long>(r.body_dropped),
      r.fallen, r.spills, r.drops);
}

void run_demo(const DemoArgs& a) {
  graphs::TableTaskConfig config;
  config.task =
      a.task == "clear-table" ? graphs::TableTask::CLEAR_TABLE : graphs::TableTask::SERVE_A_MEAL;
  config.objects = a.objects;
  config.keep = a.keep;
  config.bring = a.categories;
  if (config.task == graphs::TableTask::SERVE_A_MEAL && config.bring.empty()) {
    std::cerr << "orthoflow demo: serve-a-meal needs --categories (what to bring)\n";
    throw CLI::RuntimeError(EXIT_USAGE);
  }
  if (a.event == "move-target") config.event = graphs::TaskEvent::MOVE_TARGET;
  if (a.event == "stop-perception") config.event = graphs::TaskEvent::STOP_PERCEPTION;
  if (a.event == "unplug-arm") config.event = graphs::TaskEvent::UNPLUG_ARM;
  for (std::size_t p = 0; p < manipulation::PHASE_COUNT; ++p) {
    const auto phase = static_cast<manipulation::Phase>(p);
    if (a.event_phase == manipulation::to_string(phase)) config.event_phase = phase;
  }
  if (!a.robot_frames.empty()) {
    auto frames = manipulation::load_robot_frames(a.robot_frames);
    if (!frames) {
      std::cerr << "orthoflow demo: " << frames.error() << '\n';
      throw CLI::RuntimeError(EXIT_USAGE);
    }
    config.robot_base_from_camera = frames->base_from_camera;
  }
  DemoMarks marks;
  if (config.task == graphs::TableTask::CLEAR_TABLE)
    marks.area = &config.area;
  else
    marks.user_place = &config.user_place;
  nlohmann::json all = nlohmann::json::array();
  std::size_t moves = 0, placed = 0, refused = 0, stopped = 0, retries = 0, placed_on_retry = 0;
  double placed_seconds = 0.0;
  std::map<std::string, std::size_t> failures;
  for (std::uint32_t k = 0; k < a.scenes; ++k) {
    config.seed = a.seed + k;
    std::string picture_error;
    if (!a.pictures.empty()) {
      const std::filesystem::path dir = a.scenes == 1 ? std::filesystem::path(a.pictures)
                                                      : std::filesystem::path(a.pictures) /
                                                            ("seed" + std::to_string(config.seed));
      std::error_code ec;
      std::filesystem::create_directories(dir, ec);
      config.on_frame = [&, dir](const graphs::TaskFrameView& view) {
        if (view.frame % a.picture_every != 0 || !picture_error.empty()) return;
        char name[32];
        std::snprintf(name, sizeof name, "frame%05llu.png",
                      static_cast<unsigned long long>(view.frame));
        if (auto ok = write_demo_picture(view, marks, (dir / name).string()); !ok)
          picture_error = ok.error();
      };
    }
    auto report = graphs::run_table_task(config);
    if (!report) {
      std::cerr << "orthoflow demo: " << report.error() << '\n';
      throw CLI::RuntimeError(EXIT_FAILURE_GENERIC);
    }
    if (!picture_error.empty()) {
      std::cerr << "orthoflow demo: " << picture_error << '\n';
      throw CLI::RuntimeError(EXIT_FAILURE_GENERIC);
    }
    const graphs::TableTaskReport& r = *report;
    if (a.json)
      all.push_back(to_json(r));
    else
      print(r);
    refused += r.refused.empty() ? 0 : 1;
    stopped += r.stopped.empty() ? 0 : 1;
    // Per object to move: its last attempt (a failed move is retried once, at the end).
    std::vector<const graphs::MoveReport*> last(r.first_moves(), nullptr);
    for (const graphs::MoveReport& m : r.moves) {
      if (m.attempt == 1) {
        ++moves;
        last[static_cast<std::size_t>(&m - r.moves.data())] = &m;
      } else {
        ++retries;
        last[m.retry_of] = &m;
      }
    }
    for (const graphs::MoveReport* m : last) {
      if (m->arrived) {
        ++placed;
        placed_seconds += m->seconds;
        if (m->attempt > 1) ++placed_on_retry;
      } else {
        ++failures[m->failure.empty() ? std::string("not at the spot") : m->failure];
      }
    }
  }
  if (a.json) {
    nlohmann::json f = nlohmann::json::object();
    for (const auto& [why, count] : failures) f[why] = count;
    std::cout << nlohmann::json{{"runs", all},
                                {"summary",
                                 {{"scenes", a.scenes},
                                  {"moves", moves},
                                  {"placed", placed},
                                  {"retries", retries},
                                  {"placed_on_retry", placed_on_retry},
                                  {"mean_seconds_per_placed",
                                   placed ? placed_seconds / static_cast<double>(placed) : 0.0},
                                  {"refused", refused},
                                  {"stopped", stopped},
                                  {"failures", f}}}}
                     .dump()
              << '\n';
  } else if (a.scenes > 1) {
    std::printf(
        "%u scenes: %zu of %zu objects placed (%.1f %%; %zu on a retry, of %zu retried), %.1f s "
        "per placed object; %zu refused, %zu stopped\n",
        a.scenes, placed, moves,
        moves ? 100.0 * static_cast<double>(placed) / static_cast<double>(moves) : 0.0,
        placed_on_retry, retries, placed ? placed_seconds / static_cast<double>(placed) : 0.0,
        refused, stopped);
    for (const auto& [why, count] : failures)
      std::printf("  failed: %zu x %s\n", count, why.c_str());
  }
  if (refused == a.scenes) throw CLI::RuntimeError(EXIT_FAILURE_GENERIC);
}

}  // namespace

void add_demo_command(CLI::App& app) {
  auto a = std::make_shared<DemoArgs>();
  auto* cmd = app.add_subcommand(
      "demo",
      "run clear-table or serve-a-meal end to end on the simulated Kinect and JACO: teach, "
      "recognise, plan, grasp, carry, place (docs/MANIPULATION.md)");
  cmd->add_option("task", a->task, "clear-table or serve-a-meal")
      ->required()
      ->check(CLI::IsMember({"clear-table", "serve-a-meal"}));
  cmd->add_option("--categories", a->categories, "serve-a-meal: the categories to bring, in order")
      ->delimiter(',');
  cmd->add_option("--keep", a->keep, "clear-table: table items that stay (default plate)")
      ->delimiter(',');
  cmd->add_option("--seed", a->seed, "the first scene's seed")->capture_default_str();
  cmd->add_option("--objects", a->objects, "objects on the table")
      ->check(CLI::Range(3, 8))
      ->capture_default_str();
  cmd->add_option("--scenes", a->scenes, "scenes to run (seeds seed, seed+1, ...)")
      ->check(CLI::Range(1, 1000))
      ->capture_default_str();
  cmd->add_option("--event", a->event, "trouble during the first move")
      ->check(CLI::IsMember({"none", "move-target", "stop-perception", "unplug-arm"}))
      ->capture_default_str();
  cmd->add_option("--event-phase", a->event_phase, "the first move's phase the event comes in")
      ->check(CLI::IsMember({"go_initial", "open", "pre_grasp", "approach", "close", "lift",
                             "carry", "place", "release", "retreat"}))
      ->capture_default_str();
  cmd->add_option("--pictures", a->pictures, "write the world from above as PNG frames here");
  cmd->add_option("--picture-every", a->picture_every, "every Nth frame")
      ->check(CLI::Range(1, 1000))
      ->capture_default_str();
  cmd->add_option("--robot-frames", a->robot_frames,
                  "the robot's calibration (calibrate hand-eye --out); the world keeps the truth");
  cmd->add_flag("--json", a->json, "one JSON document");
  cmd->callback([a] { run_demo(*a); });
}

}  // namespace orthoflow::apps
