// `orthoflow arm home | retract | move --joints ... | move --pose ... | fingers open|close|a,b,c`:
// motion through orthoflow's JACO driver. The command holds the arm (its state directory) until the
// motion ends and feeds the driver's watchdog every 20 ms, so if this process dies the arm stops
// within 100 ms; SIGINT, SIGTERM, SIGHUP, SIGQUIT and `orthoflow arm stop` halt it in place and
// latch the stop. The safety monitor checks every cycle (docs/SAFETY.md); a refusal names the
// limit and the part, and nothing moves. Every command ends by --timeout at the latest.
#include <atomic>
#include <chrono>
#include <csignal>
#include <functional>
#include <iostream>
#include <optional>
#include <thread>

#include "apps/arm_cli.hpp"

namespace orthoflow::apps::arm_cli {
namespace {

namespace jaco = drivers::jaco;

/// What a wait loop asks after every look at the arm: nullopt to keep waiting, "" when the command
/// is done, or why it failed.
using DoneCheck = std::function<std::optional<std::string>(const jaco::ArmSnapshot&)>;

/// Submits @p command, then waits until @p done says so, feeding the watchdog every 20 ms. A signal
/// (SIGINT, SIGTERM, SIGHUP, SIGQUIT: start_arm installed them) or `orthoflow arm stop` halts the
/// arm in place and latches it; a fault or --timeout ends the wait (the timeout stops the arm).
jaco::ArmSnapshot submit_and_wait(jaco::JacoArm& arm, const jaco::ArmCommand& command,
                                  const ArmArgs& a, const DoneCheck& done) {
  if (auto ok = arm.submit(command); !ok.has_value()) {
    const int code =
        ok.error().code == jaco::JacoError::Code::REFUSED ? EXIT_USAGE : EXIT_FAILURE_GENERIC;
    fail(jaco::to_string(ok.error()), code);
  }
  const auto deadline =
      std::chrono::steady_clock::now() + std::chrono::duration<double>(a.timeout_s);
  jaco::ArmSnapshot s = arm.snapshot();
  std::string failure;
  for (;;) {
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
    // A signal (the arm's guard halted it already) or a stop request from another process.
    if (const std::string latched = arm.latch_reason(); !latched.empty()) {
      arm.persist_latch();
      failure = "stopped (" + latched +
                "): the arm is halted in place and the stop latched "
                "until `orthoflow arm reset`";
      break;
    }
    arm.keep_alive();
    s = arm.snapshot();
    if (s.fault) {
      failure = "the arm faulted: " + jaco::to_string(s.fault_error);
      break;
    }
    if (const auto verdict = done(s)) {
      failure = *verdict;
      break;
    }
    if (std::chrono::steady_clock::now() > deadline) {
      (void)arm.submit(jaco::ArmCommand{jaco::ArmCommand::Kind::STOP});
      std::this_thread::sleep_for(std::chrono::milliseconds(50));
      failure = "timed out after " + std::to_string(a.timeout_s) +
                " s (raise it with --timeout); "
                "stopped";
      break;
    }
  }
  if (!failure.empty()) fail(failure);
  return s;
}

/// Joint, pose and HOME / RETRACT commands: done when the controller is idle again.
void run_until_done(jaco::JacoArm& arm, const jaco::ArmCommand& command, const ArmArgs& a) {
  const std::uint64_t start_cycle = arm.snapshot().cycle;
  const jaco::ArmSnapshot s =
      submit_and_wait(arm, command, a, [start_cycle](const jaco::ArmSnapshot& now) {
        if (now.control != jaco::ControlState::IDLE || now.cycle <= start_cycle + 2)
          return std::optional<std::string>{};
        if (now.last_stop == jaco::StopReason::REACHED) return std::optional<std::string>{""};
        std::string why = std::string("the motion ended: ") + jaco::to_string(now.last_stop);
        if (now.last_stop == jaco::StopReason::SAFETY)
          why += " (the safety monitor: " + jaco::describe(now.violation) + ")";
        return std::optional<std::string>{why};
      });
  if (a.json) {
    std::cout << snapshot_json(s).dump(2) << '\n';
    return;
  }
  std::cout << "done: " << jaco::to_string(s.arm_state) << ", joints";
  for (double q : s.joints) std::cout << ' ' << q;
  std::cout << " deg, xyz " << s.pose.position.x() << ' ' << s.pose.position.y() << ' '
            << s.pose.position.z() << " m\n";
}

void run_home(const ArmArgs& a, bool retract) {
  auto arm = start_arm(a);
  jaco::ArmCommand command;
  command.kind = retract ? jaco::ArmCommand::Kind::RETRACT : jaco::ArmCommand::Kind::HOME;
  run_until_done(*arm, command, a);
}

void run_move(const ArmArgs& a) {
  if (a.joints.empty() == a.pose.empty())
    fail("move needs exactly one of --joints or --pose", EXIT_USAGE);
  jaco::ArmCommand command;
  command.speed_fraction = a.speed;
  if (!a.joints.empty()) {
    const auto q = parse_numbers(a.joints, jaco::JOINTS, "--joints");
    command.kind = jaco::ArmCommand::Kind::MOVE_JOINTS;
    for (std::size_t j = 0; j < jaco::JOINTS; ++j) command.joints[j] = q[j];
  } else {
    const auto p = parse_numbers(a.pose, 6, "--pose");
    command.kind = jaco::ArmCommand::Kind::MOVE_POSE;
    command.pose.position = {p[0], p[1], p[2]};
    command.pose.theta = {p[3], p[4], p[5]};
  }
  auto arm = start_arm(a);
  run_until_done(*arm, command, a);
}

void run_fingers(const ArmArgs& a) {
  auto arm = start_arm(a);
  const double closed = jaco::finger_closed(arm->identity().model);
  jaco::ArmCommand command;
  command.kind = jaco::ArmCommand::Kind::MOVE_FINGERS;
  if (a.fingers == "open") {
    command.fingers = {0.0, 0.0, 0.0};
  } else if (a.fingers == "close") {
    command.fingers = {closed, closed, closed};
  } else {
    const auto f = parse_numbers(a.fingers, jaco::FINGERS, "fingers");
    command.fingers = {f[0], f[1], f[2]};
  }
  // Finger moves end when the fingers arrive: wait on them instead of the joint controller.
  const jaco::ArmSnapshot s =
      submit_and_wait(*arm, command, a, [&command, closed](const jaco::ArmSnapshot& now) {
        double error = 0.0;
        for (std::size_t f = 0; f < jaco::FINGERS; ++f)
          error = std::max(error, std::abs(now.fingers[f] - command.fingers[f]));
        return error <= 0.02 * closed ? std::optional<std::string>{""}
                                      : std::optional<std::string>{};
      });
  if (a.json) {
    std::cout << snapshot_json(s).dump(2) << '\n';
    return;
  }
  std::cout << "fingers " << s.fingers[0] << ' ' << s.fingers[1] << ' ' << s.fingers[2] << '\n';
}

/// The options of a motion command: it holds the arm as @p what; signals halt it.
ArmArgs moving(ArmArgs a, const char* what) {
  a.what = what;
  a.motion = true;
  return a;
}

void add_motion_options(CLI::App* sub, const std::shared_ptr<ArmArgs>& a) {
  add_common_options(sub, a);
  sub->add_option("--timeout", a->timeout_s, "give up and stop after this many seconds");
  sub->add_option("--keep-out", a->keep_out,
                  "a box the hand must not enter: x0,y0,z0,x1,y1,z1[,name] (m, base frame; "
                  "repeatable)");
  sub->add_option("--workspace", a->workspace, "the box the hand must stay in: x0,y0,z0,x1,y1,z1");
  sub->add_option("--frames", a->frames, "robot frames file: places the camera's keep-out");
}

}  // namespace

void add_motion_commands(CLI::App* arm, const std::shared_ptr<ArmArgs>& a) {
  auto* home = arm->add_subcommand("home", "drive to HOME (from NOINIT too) by the virtual button");
  add_motion_options(home, a);
  home->callback([a] { run_home(moving(*a, "orthoflow arm home"), false); });
  auto* retract = arm->add_subcommand("retract", "drive from HOME to RETRACT");
  add_motion_options(retract, a);
  retract->callback([a] { run_home(moving(*a, "orthoflow arm retract"), true); });
  auto* move = arm->add_subcommand("move", "move to joint angles or a Cartesian pose");
  add_motion_options(move, a);
  move->add_option("--joints", a->joints, "six actuator angles in degrees: a,b,c,d,e,f");
  move->add_option("--pose", a->pose, "x,y,z (m) and theta x,y,z (rad), base frame");
  move->add_option("--speed", a->speed, "fraction of the joint speed cap, (0, 1]");
  auto* fingers = arm->add_subcommand("fingers", "open, close, or move the fingers to a,b,c");
  add_motion_options(fingers, a);
  fingers->add_option("target", a->fingers, "open | close | a,b,c")->required();
  fingers->callback([a] { run_fingers(moving(*a, "orthoflow arm fingers")); });
  move->callback([a] { run_move(moving(*a, "orthoflow arm move")); });
}

}  // namespace orthoflow::apps::arm_cli
