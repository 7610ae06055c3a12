// The closed loop of `orthoflow demo` (graphs/sessions/table_task_session.hpp) on the simulators:
// the world starts as the robot frames file describes it, a task naming a category nobody taught is
// refused, and an arm unplugged during the first move stops the task with the arm's fault, nothing
// moving after it. (Whole tasks take minutes of simulated frames: their numbers come from
// `orthoflow demo
// --scenes 10`, docs/MANIPULATION.md.)
#include <gtest/gtest.h>

#include "graphs/sessions/table_task_session.hpp"
#include "manipulation/robot_frames.hpp"

namespace orthoflow::graphs {
namespace {

constexpr const char* FRAMES_FILE = ORTHOFLOW_SOURCE_DIR "/config/robot_frames_synthetic.yaml";

TEST(TableTaskSession, TheSyntheticTableMatchesTheRobotFramesFile) {
  const auto frames = manipulation::load_robot_frames(FRAMES_FILE);
  ASSERT_TRUE(frames) << frames.error();
  const Eigen::Isometry3d x = synthetic_base_from_camera(simulation::TableSpec{});
  // The table is tilted 0.785 rad; the file says 45 degrees: 4e-4 apart.
  EXPECT_TRUE(x.isApprox(frames->base_from_camera, 2e-3)) << x.matrix();
}

TEST(TableTaskSession, ACategoryNobodyTaughtIsRefusedBeforeAnythingMoves) {
  TableTaskConfig config;
  config.task = TableTask::SERVE_A_MEAL;
  config.bring = {"pizza"};
  config.seed = 3;
  const auto report = run_table_task(config);
  ASSERT_TRUE(report) << report.error();
  EXPECT_EQ(report->refused, "nobody taught the category 'pizza'");
  EXPECT_TRUE(report->moves.empty());
  EXPECT_EQ(report->taught, report->scene.size());  // the person taught every object first
}

TEST(TableTaskSession, AnArmUnpluggedDuringTheFirstMoveStopsTheTask) {
  TableTaskConfig config;
  config.seed = 1;
  config.event = TaskEvent::UNPLUG_ARM;
  config.event_phase = manipulation::Phase::PRE_GRASP;
  const auto report = run_table_task(config);
  ASSERT_TRUE(report) << report.error();
  ASSERT_FALSE(report->moves.empty());
  EXPECT_EQ(report->moves[0].failure, "arm_fault");
  EXPECT_FALSE(report->moves[0].held);
  EXPECT_NE(report->stopped.find("arm_fault"), std::string::npos) << report->stopped;
  for (std::size_t k = 1; k < report->moves.size(); ++k)
    EXPECT_EQ(report->moves[k].failure, "not started: the task stopped");
  EXPECT_GT(report->body_dropped, 0U);  // no fresh arm state: the body filter drops, never guesses
}

TEST(TableTaskSession, PerceptionThatStopsAbortsTheMoveBeforeTheObjectIsHeld) {
  TableTaskConfig config;
  config.seed = 1;
  config.event = TaskEvent::STOP_PERCEPTION;
  config.event_phase = manipulation::Phase::PRE_GRASP;
  const auto report = run_table_task(config);
  ASSERT_TRUE(report) << report.error();
  ASSERT_FALSE(report->moves.empty());
  EXPECT_EQ(report->moves[0].failure, "perception_stale");
  EXPECT_FALSE(report->moves[0].held);
}

}  // namespace
}  // namespace orthoflow::graphs
