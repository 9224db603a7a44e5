// The black box of an arm with several joints (issue 14): the engine records every joint's set
// point, input and chamber set points in each tick, the session file keeps every joint (joint 1's
// columns as always, then `_j<j>` columns per joint, sessions/record_columns), and the CSV and MAT
// exports write every joint. A one-joint black box is exactly what it always was.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <sstream>

#include "devices/simulated_arm_chain.hpp"
#include "engine/rt/engine_core.hpp"
#include "engine/rt/engine_driver.hpp"
#include "engine/model/pneumatic_arm_chain_parameters.hpp"
#include "sessions/black_box_file.hpp"
#include "sessions/record_columns.hpp"
#include "sessions/session_export.hpp"
#include "sessions/session_store.hpp"
#include "tests/session_test_support.hpp"

namespace bellows {
namespace {

namespace fs = std::filesystem;
using testing::TempDir;

/// A session on the `preset` arm stopped by the operator one second into its first trial: no
/// iteration completed, one black box with every joint moving.
Session stopped_arm_session(const char* preset, const char* trajectory_name) {
  Configuration config;
  config.arm.preset = preset;
  SimulatedArmChain arm(pneumatic_chain_of(config.plant, config.arm), 5);
  EngineCore core(arm, config.controller, config.timing, config.safety);
  SimulatedClock clock(core, arm);
  const Trajectory trajectory = library_trajectory(trajectory_name, config.timing.sample_s());
  EXPECT_TRUE(core.send(EngineCommand::select_trajectory(trajectory)));
  EXPECT_TRUE(core.send(EngineCommand::of(CommandKind::kArm)));
  clock.step(200);
  TrialRecord record;
  record.prepare(trajectory.learning_samples(), config.timing.ticks_per_sample, trajectory.joints());
  const Eigen::MatrixXd correction =
      Eigen::MatrixXd::Constant(trajectory.learning_samples(), trajectory.joints(), 0.01);
  EXPECT_TRUE(core.send(EngineCommand::start_trial(trajectory, correction, record, 0, 1)));
  clock.step(std::lround(1.0 / config.timing.tick_s));  // the arm's moves start at 0.6 s
  core.request_emergency_stop();
  clock.step();
  EXPECT_EQ(core.state(), EngineState::kFault);

  Session session;
  SessionManifest& m = session.manifest;
  m.program_version = program_version();
  m.name = preset;
  m.device = arm.name();
  m.started_utc = utc_now();
  m.updated_utc = m.started_utc;
  m.configuration = config;
  m.joints = trajectory.joints();
  m.trajectory_name = trajectory.name;
  m.trajectory_samples = trajectory.learning_samples();
  session.trajectory = trajectory;
  session.black_boxes.push_back(core.black_box().copy_frozen());
  m.black_boxes.push_back({utc_now(), 0, "emergency-stop", static_cast<int>(session.black_boxes.back().size())});
  return session;
}

/// Angles go through degrees in the file: an ulp at most, as in the iteration files.
bool within_an_ulp(double a, double b) {
  return a == b || a == std::nextafter(b, 1e300) || a == std::nextafter(b, -1e300);
}

/// Every value a black box file keeps, for every joint (angles to an ulp, the rest exactly).
void expect_same_joint_ticks(const std::vector<TickRecord>& loaded, const std::vector<TickRecord>& saved, int joints) {
  ASSERT_EQ(loaded.size(), saved.size());
  for (std::size_t i = 0; i < saved.size(); ++i) {
    const TickRecord& a = loaded[i];
    const TickRecord& b = saved[i];
    ASSERT_EQ(a.reading.joint_count, joints);
    EXPECT_EQ(a.tick, b.tick);
    EXPECT_EQ(a.state, b.state);
    EXPECT_EQ(a.fault, b.fault);
    EXPECT_EQ(a.sample, b.sample);
    EXPECT_EQ(a.reading.supply_bar, b.reading.supply_bar);
    for (int j = 0; j < joints; ++j) {
      const auto ji = static_cast<std::size_t>(j);
      SCOPED_TRACE("tick " + std::to_string(i) + ", joint " + std::to_string(j + 1));
      EXPECT_TRUE(within_an_ulp(a.reading.joint[ji].angle_rad, b.reading.joint[ji].angle_rad))
          << a.reading.joint[ji].angle_rad - b.reading.joint[ji].angle_rad;
      EXPECT_EQ(a.reading.joint[ji].chamber_bar, b.reading.joint[ji].chamber_bar);
      EXPECT_EQ(a.joint(j).desired_rad, b.joint(j).desired_rad);
      EXPECT_EQ(a.joint(j).u_total_bar, b.joint(j).u_total_bar);
      EXPECT_EQ(a.joint(j).setpoints.a_bar, b.joint(j).setpoints.a_bar);
      EXPECT_EQ(a.joint(j).setpoints.b_bar, b.joint(j).setpoints.b_bar);
      EXPECT_EQ(a.valves.joint[ji].inlet_duty, b.valves.joint[ji].inlet_duty);
      EXPECT_EQ(a.valves.joint[ji].outlet_duty, b.valves.joint[ji].outlet_duty);
    }
  }
}

std::string first_line(const std::string& text) { return text.substr(0, text.find('\n')); }

std::string joined(const std::vector<std::string>& names) {
  std::string out;
  for (const std::string& name : names) out += (out.empty() ? "" : ",") + name;
  return out;
}

TEST(BlackBoxJoints, OneJointKeepsTheColumnsOfEverySessionSavedSoFar) {
  EXPECT_EQ(
      joined(black_box_header(1)),
      "tick,time_s,sensor_time_s,state,fault,angle_deg,angle_setpoint_deg,pressure_a_bar,pressure_b_bar,supply_bar,"
      "u_tot_bar,pressure_a_setpoint_bar,pressure_b_setpoint_bar,inlet_a_duty,outlet_a_duty,inlet_b_duty,"
      "outlet_b_duty,sample,trial_id");
  EXPECT_EQ(joined(black_box_header(2)),
            joined(black_box_header(1)) +
                ",angle_deg_j2,angle_setpoint_deg_j2,pressure_a_bar_j2,pressure_b_bar_j2,u_tot_bar_j2,"
                "pressure_a_setpoint_bar_j2,pressure_b_setpoint_bar_j2,inlet_a_duty_j2,"
                "outlet_a_duty_j2,inlet_b_duty_j2,outlet_b_duty_j2");
  const std::string docs = testing::read_text(fs::path(BELLOWS_SOURCE_DIR) / "docs" / "session-format.md");
  for (const TickColumn& column : black_box_record_columns()) {
    EXPECT_NE(docs.find("`" + std::string(column.name) + "`"), std::string::npos) << column.name;
  }
}

class BlackBoxJointSessions : public ::testing::TestWithParam<std::pair<const char*, const char*>> {};

TEST_P(BlackBoxJointSessions, EveryJointIsRecordedSavedLoadedAndExported) {
  const auto [preset, trajectory_name] = GetParam();
  const Session saved = stopped_arm_session(preset, trajectory_name);
  const std::vector<TickRecord>& box = saved.black_boxes[0];
  const int joints = saved.manifest.joints;
  const int last = joints - 1;
  ASSERT_FALSE(box.empty());
  EXPECT_EQ(black_box_joints(box), joints);
  // The engine recorded every joint's own set point, input and chamber set points: the last
  // joint's differ from joint 1's while the trial runs (its correction and PID are its own).
  const TickRecord& running = box[box.size() / 2];
  EXPECT_EQ(running.state, EngineState::kRunning);
  EXPECT_NE(running.joint(last).u_total_bar, 0.0);
  EXPECT_NE(running.joint(last).u_total_bar, running.joint(0).u_total_bar);
  EXPECT_NE(running.joint(last).setpoints.a_bar, running.joint(0).setpoints.a_bar);
  EXPECT_NE(running.joint(last).setpoints.a_bar, 0.0);

  TempDir dir;
  save_session(saved, dir / "s");
  const std::string file = testing::read_text(dir / "s" / "faults" / "blackbox_0000.csv");
  EXPECT_EQ(first_line(file), joined(black_box_header(joints)));
  const Session loaded = load_session(dir / "s");
  ASSERT_EQ(loaded.black_boxes.size(), 1u);
  expect_same_joint_ticks(loaded.black_boxes[0], box, joints);
  EXPECT_EQ(format_black_box_csv(loaded.black_boxes[0]), file) << "written again, the same bytes";

  // The CSV export stacks the boxes with every joint's columns.
  const std::vector<fs::path> csv = export_session_csv(loaded, dir / "out.csv");
  ASSERT_EQ(csv.size(), 4u);
  EXPECT_EQ(first_line(testing::read_text(csv[3])), "black_box," + joined(black_box_header(joints)));

  // The MAT export, read by scipy: the last joint's columns of the fault tick.
  export_session_mat(loaded, dir / "out.mat");
  testing::write_text(dir / "read.py", R"(
import sys
from scipy.io import loadmat
m = loadmat(sys.argv[1], squeeze_me=True, struct_as_record=False)
t = m["black_boxes"].ticks
j = sys.argv[2]
print(t.__dict__["u_tot_bar_j" + j][-2], t.__dict__["pressure_b_setpoint_bar_j" + j][-2], t.__dict__["outlet_b_duty_j" + j][-1])
)");
  FILE* pipe = ::popen(("/usr/bin/python3 " + (dir / "read.py").string() + " " + (dir / "out.mat").string() + " " +
                        std::to_string(joints) + " 2>&1")
                           .c_str(),
                       "r");
  ASSERT_NE(pipe, nullptr);
  char buffer[512] = {};
  const std::size_t got = std::fread(buffer, 1, sizeof buffer - 1, pipe);
  ::pclose(pipe);
  std::istringstream read(std::string(buffer, got));
  double u_total = 0, setpoint_b = 0, outlet_b = 0;
  read >> u_total >> setpoint_b >> outlet_b;
  ASSERT_FALSE(read.fail()) << std::string(buffer, got);
  const TickRecord& before_stop = box[box.size() - 2];
  EXPECT_EQ(u_total, before_stop.joint(last).u_total_bar);
  EXPECT_EQ(setpoint_b, before_stop.joint(last).setpoints.b_bar);
  EXPECT_EQ(outlet_b, 1.0) << "the fault tick vents every joint";
}

INSTANTIATE_TEST_SUITE_P(Arms, BlackBoxJointSessions,
                         ::testing::Values(std::pair{"arm2", "paper2"}, std::pair{"arm3", "paper3"}),
                         [](const auto& arm) { return std::string(arm.param.first); });

}  // namespace
}  // namespace bellows
