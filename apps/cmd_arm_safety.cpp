// `orthoflow arm stop | reset | limits` (docs/SAFETY.md): the stop any process can reach, the
// person's reset of a latched stop, and the limits the monitor enforces.
// - stop: with a holder (the state directory names it), asks it over iceoryx
//   (graphs/services/arm_stop_service.hpp), else by SIGTERM, which every motion command and
//   `task run` turn into a halt in place and a latch; fails when it reaches neither. With no
//   holder it opens the arm itself: halts it, erases the FIFO, releases the joystick, latches.
// - reset: clears the latch, holding the arm meanwhile (refused while another process holds it).
// - limits: the active limits (the file, --workspace, --keep-out; --frames places the camera).
#include <signal.h>
#include <unistd.h>

#include <chrono>
#include <iostream>
#include <thread>

#include "apps/arm_cli.hpp"
#include "engine/ipc_runtime.hpp"

namespace orthoflow::apps::arm_cli {
namespace {

namespace jaco = drivers::jaco;
using namespace std::chrono_literals;

struct StopReport {
  std::string via;  ///< iceoryx | signal | device
  bool was_moving = false;
  long holder_pid = 0;
  std::string holder;
  double ms = -1.0;  ///< request to halt, where measured
};

void print(const StopReport& r, bool json) {
  if (json) {
    nlohmann::json out = {{"stopped", true},
                          {"via", r.via},
                          {"was_moving", r.was_moving},
                          {"holder_pid", r.holder_pid},
                          {"holder", r.holder},
                          {"latched", true}};
    if (r.ms >= 0.0) out["request_to_halt_ms"] = r.ms;
    std::cout << out.dump() << '\n';
    return;
  }
  if (r.via == "device")
    std::cout << "no process held the arm: opened it, halted it, erased the trajectory FIFO, "
                 "released the joystick";
  else
    std::cout << "stopped the arm held by pid " << r.holder_pid << " (" << r.holder << ") via "
              << r.via;
  std::cout << "; it was " << (r.was_moving ? "moving" : "not moving");
  if (r.ms >= 0.0) std::cout << "; halted " << r.ms << " ms after the request";
  std::cout << "; the stop is latched until `orthoflow arm reset`\n";
}

bool stop_over_iceoryx(const jaco::ArmHolder& holder, const std::string& reason, StopReport& r) {
  if (!engine::ipc_runtime_ready()) {
    if (!engine::probe_roudi()) return false;
    if (!engine::init_ipc_runtime("orthoflow_arm_stop_" + std::to_string(::getpid()))) return false;
  }
  auto outcome = graphs::request_arm_stop(reason, 1500ms, static_cast<int>(holder.pid));
  if (!outcome || outcome->status != graphs::ArmStopOutcome::Status::STOPPED) return false;
  r = {"iceoryx", outcome->was_moving, outcome->holder_pid, outcome->holder,
       1e-6 * static_cast<double>(outcome->halted_ns - outcome->request_ns)};
  return true;
}

// SIGTERM: a motion command or `task run` halts and latches; a holder that moves nothing (`arm
// state --follow`) closes the arm, which erases the FIFO and releases the joystick.
enum class Signalled { LATCHED, RELEASED, NO };
Signalled stop_by_signal(const jaco::ArmStateDir& dir, const jaco::ArmHolder& holder,
                         StopReport& r) {
  if (holder.pid <= 0 || ::kill(static_cast<pid_t>(holder.pid), SIGTERM) != 0) return Signalled::NO;
  const auto deadline = std::chrono::steady_clock::now() + 3s;
  while (std::chrono::steady_clock::now() < deadline) {
    if (auto latch = dir.latched(); latch && latch->pid == holder.pid) {
      r = {"signal", latch->was_moving, holder.pid, holder.what, -1.0};
      return Signalled::LATCHED;
    }
    if (!dir.holder()) return Signalled::RELEASED;
    std::this_thread::sleep_for(5ms);
  }
  return Signalled::NO;
}

void run_stop(ArmArgs a) {
  auto dir = jaco::ArmStateDir::open(state_dir_path(a));
  if (!dir) fail(dir.error());
  const std::string reason = "orthoflow arm stop";
  StopReport r;
  if (auto holder = dir->holder()) {
    bool stopped = stop_over_iceoryx(*holder, reason, r);
    if (!stopped) {
      const Signalled s = stop_by_signal(*dir, *holder, r);
      if (s == Signalled::NO)
        fail("could not reach the process holding the arm, pid " + std::to_string(holder->pid) +
                 " (" + holder->what + "): no answer over iceoryx, none to SIGTERM",
             EXIT_UNREACHABLE);
      stopped = s == Signalled::LATCHED;
    }
    if (stopped) return print(r, a.json);
  }
  a.what = "orthoflow arm stop";
  HeldArm arm = start_arm(a);
  r.via = "device";
  r.was_moving = arm->estop(reason);  // halts, erases the FIFO; closing releases the joystick
  arm.reset();
  print(r, a.json);
}

void run_reset(ArmArgs a) {
  auto dir = jaco::ArmStateDir::open(state_dir_path(a));
  if (!dir) fail(dir.error());
  const auto latch = dir->latched();
  if (!latch) {
    std::cout << (a.json ? "{\"reset\":false,\"latched\":false}" : "no stop is latched") << '\n';
    return;
  }
  a.what = "orthoflow arm reset";
  HeldArm arm = start_arm(a);
  if (auto ok = arm->reset_estop(); !ok) fail("cannot reset: " + jaco::to_string(ok.error()));
  arm.reset();
  if (a.json) {
    std::cout << nlohmann::json{{"reset", true},
                                {"latched_by", latch->reason},
                                {"pid", latch->pid},
                                {"unix_s", latch->unix_s}}
                     .dump()
              << '\n';
    return;
  }
  std::cout << "cleared the stop latched by " << latch->reason << " (pid " << latch->pid
            << "); the arm may move again\n";
}

void run_limits(const ArmArgs& a) {
  const manipulation::ArmLimitsFile file = load_limits(a);
  if (!a.json) {
    std::cout << manipulation::describe_limits(file);
    return;
  }
  const jaco::SafetyLimits& l = file.limits;
  const auto vec = [](const Eigen::Vector3d& v) {
    return std::vector<double>{v.x(), v.y(), v.z()};
  };
  nlohmann::json boxes = nlohmann::json::array();
  for (std::size_t i = 0; i < l.keep_out_count; ++i)
    boxes.push_back({{"name", std::string(l.keep_out[i].name.view())},
                     {"min_m", vec(l.keep_out[i].min)},
                     {"max_m", vec(l.keep_out[i].max)},
                     {"from", jaco::to_string(l.keep_out[i].from)}});
  std::cout << nlohmann::json{{"source", file.source},
                              {"workspace_m", {vec(l.workspace.min), vec(l.workspace.max)}},
                              {"table_height_m", file.table_height_m},
                              {"speed_deg_s", l.max_joint_speed_deg_s},
                              {"accel_deg_s2", l.max_joint_accel_deg_s2},
                              {"brake_decel_deg_s2", l.brake_decel_deg_s2},
                              {"command_latency_ms", 1e-6 * double(l.command_latency_ns)},
                              {"keep_out", boxes},
                              {"removed", file.removed}}
                   .dump()
            << '\n';
}

}  // namespace

void add_safety_commands(CLI::App* arm, const std::shared_ptr<ArmArgs>& a) {
  auto* stop = arm->add_subcommand(
      "stop",
      "halt the arm in place and latch the stop: asks the process holding it (iceoryx, "
      "else SIGTERM), or opens the arm when nobody holds it");
  add_common_options(stop, a);
  stop->callback([a] { run_stop(*a); });
  auto* reset = arm->add_subcommand("reset", "clear a latched stop (a person, after checking)");
  add_common_options(reset, a);
  reset->callback([a] { run_reset(*a); });
  auto* limits = arm->add_subcommand("limits", "print the limits the safety monitor enforces");
  add_common_options(limits, a);
  limits->add_option("--keep-out", a->keep_out, "one more box: x0,y0,z0,x1,y1,z1[,name]");
  limits->add_option("--workspace", a->workspace, "the workspace: x0,y0,z0,x1,y1,z1");
  limits->add_option("--frames", a->frames, "robot frames file: places the camera's keep-out");
  limits->callback([a] { run_limits(*a); });
}

}  // namespace orthoflow::apps::arm_cli
