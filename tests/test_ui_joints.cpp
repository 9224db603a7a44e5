// The console on an arm with several joints (issue 14): the joint selector, per-joint and overall
// RMS, the correction per joint through the engine, the inspector and the live strip on joint 2,
// and guards that name the joint. The arm2 simulated chain drives `paper2` on a simulated clock.
#include <cmath>
#include <numbers>
#include <regex>

#include <gtest/gtest.h>

#include "devices/simulated_arm_chain.hpp"
#include "engine/model/pneumatic_arm_chain_parameters.hpp"
#include "tests/console_fixture.hpp"
#include "ui/joint_view.hpp"
#include "ui/render.hpp"

namespace bellows::ui {
namespace {

using testing::ConsoleFixture;

/// arm2, its convergence prediction on the nominal model alone: the law the console prepares is the
/// same, and the prediction's 5 x 5 grid (26 Lanczos runs on the lifted operator, ~20 s under ASan)
/// is tested where it is computed (test_joint_convergence) and reported (CliJoints.Arm2Reports...).
Configuration arm2_config() {
  Configuration c;
  c.arm.preset = "arm2";
  c.ilc.prediction_grid_points = 1;
  return c;
}

/// The arm2 chain first (the engine holds a reference to it), then the console over it.
struct Arm2Console {
  explicit Arm2Console(const Configuration& c = arm2_config()) : config(c) {}
  Configuration config;
  SimulatedArmChain chain{pneumatic_chain_of(config.plant, config.arm)};
  ConsoleFixture f{config, 3, nullptr, &chain, {}, "paper2"};
};

std::string screen_text(const ConsoleState& s) {
  std::string text;
  for (const std::string& line : render_lines(s)) text += line + "\n";
  return text;
}

TEST(UiJoints, TheSelectorCyclesThroughTheJointsAndTheHeaderNamesIt) {
  Arm2Console a;
  ConsoleFixture& f = a.f;
  EXPECT_EQ(f.state().experiment.joints(), 2);
  EXPECT_EQ(f.state().joint, 0);
  EXPECT_NE(render_lines(f.state())[0].find("joint 1/2 shoulder"), std::string::npos) << render_lines(f.state())[0];
  f.key('j');
  EXPECT_EQ(f.state().joint, 1);
  EXPECT_NE(render_lines(f.state())[0].find("joint 2/2 elbow"), std::string::npos) << render_lines(f.state())[0];
  EXPECT_NE(f.state().status.find("showing joint 2/2 elbow"), std::string::npos) << f.state().status;
  // The function bar offers it, the help lists it.
  EXPECT_NE(render_lines(f.state()).back().find("Joint"), std::string::npos) << render_lines(f.state()).back();
  f.key('j');
  EXPECT_EQ(f.state().joint, 0);
}

TEST(UiJoints, WithOneJointTheSelectorIsRefusedAndTheScreenNamesNoJoint) {
  ConsoleFixture f;
  EXPECT_EQ(f.state().experiment.joints(), 1);
  const std::string before = screen_text(f.state());
  EXPECT_EQ(before.find("joint 1"), std::string::npos) << before;
  EXPECT_EQ(render_lines(f.state()).back().find("Joint"), std::string::npos);
  f.key('j');
  EXPECT_EQ(f.state().joint, 0);
  EXPECT_NE(f.state().status.find("the arm has one joint"), std::string::npos) << f.state().status;
}

TEST(UiJoints, Arm2TrialsRecordPerJointAndOverallRmsAndLearnEveryJointsCorrection) {
  Arm2Console a;
  ConsoleFixture& f = a.f;
  f.arm_valves();
  f.run_batch(2);  // iterations 0..2
  const Experiment& e = f.state().experiment;
  ASSERT_EQ(e.trials.size(), 3u);
  for (const Trial& t : e.trials) {
    ASSERT_EQ(t.summary.joint_rms_deg.size(), 2);
    ASSERT_EQ(t.record.joint_count(), 2);
    double squares = 0.0;
    for (int j = 0; j < 2; ++j) {
      EXPECT_DOUBLE_EQ(t.summary.joint_rms_deg(j), t.record.joint_rms_error_deg(j));
      EXPECT_GT(t.summary.joint_rms_deg(j), 0.0);
      squares += t.record.joint_rms_error_deg(j) * t.record.joint_rms_error_deg(j);
      // The engine applied this trial's correction to each joint.
      ASSERT_EQ(t.correction_bar.cols(), 2);
      EXPECT_TRUE(t.record.joint_samples(j).u_ilc_bar.head(e.samples()).isApprox(t.correction_bar.col(j)) ||
                  t.correction_bar.col(j).isZero());
    }
    EXPECT_NEAR(t.summary.rms_deg, std::sqrt(squares / 2.0), 1e-12);
  }
  // Iteration 0 ran with no correction; 1 and 2 with learned ones, on both joints.
  EXPECT_TRUE(e.trials[0].correction_bar.isZero());
  for (int j = 0; j < 2; ++j) EXPECT_GT(e.trials[2].correction_bar.col(j).cwiseAbs().maxCoeff(), 0.0) << j;
  for (int j = 0; j < 2; ++j)
    EXPECT_LT(e.trials[2].summary.joint_rms_deg(j), e.trials[0].summary.joint_rms_deg(j)) << j;
  EXPECT_TRUE(f.logged("iteration 2: RMS per joint"));
  {  // At 80x24 the header keeps the joint beside the state, trajectory, iteration and RMS.
    ConsoleState small = f.state();
    small.width = kMinWidth;
    small.height = kMinHeight;
    const std::string header = render_lines(small)[0];
    EXPECT_NE(header.find("ARMED"), std::string::npos) << header;
    EXPECT_NE(header.find("paper2"), std::string::npos) << header;
    EXPECT_NE(header.find("1/2 shoulder"), std::string::npos) << header;
    EXPECT_NE(header.find(format("%.3f", e.trials.back().summary.rms_deg)), std::string::npos) << header;
  }

  // The dashboard lists every iteration's overall RMS and each joint's.
  const std::string screen = screen_text(f.state());
  EXPECT_NE(screen.find("it     all      j1     j2"), std::string::npos) << screen;
  const Trial& last = e.trials.back();
  const std::string row = format("%4d %7.3f", last.iteration, last.summary.rms_deg);
  const std::string joints = format("%7.3f%7.3f", last.summary.joint_rms_deg(0), last.summary.joint_rms_deg(1));
  EXPECT_TRUE(std::regex_search(screen, std::regex(std::regex_replace(row, std::regex("\\."), "\\.") + ".?" +
                                                   std::regex_replace(joints, std::regex("\\."), "\\."))))
      << row << joints << "\n"
      << screen;
  EXPECT_NE(screen.find(format("RMS %.3f deg", last.summary.rms_deg)), std::string::npos) << screen;
}

TEST(UiJoints, TheInspectorAndTheLiveStripShowTheSelectedJoint) {
  Arm2Console a;
  ConsoleFixture& f = a.f;
  f.arm_valves();
  f.run_batch(1);  // iterations 0..1
  f.key('c');
  ASSERT_EQ(f.state().screen, Screen::kInspector);
  f.key(key::kEnd);  // the last sample: the elbow's set point differs from the shoulder's mid-way
  for (int i = 0; i < 10; ++i) f.key(key::kPageUp);
  f.key('j');
  ASSERT_EQ(f.state().joint, 1);
  const Trial& t = f.state().experiment.trials[static_cast<std::size_t>(f.state().inspector.trial)];
  const int k = f.state().inspector.sample;
  const std::string screen = screen_text(f.state());
  EXPECT_NE(screen.find("joint 2/2 elbow"), std::string::npos) << screen;
  EXPECT_NE(screen.find(format("(joint 2 %.3f)", t.summary.joint_rms_deg(1))), std::string::npos) << screen;
  const auto readout = [](double deg) { return format("%.2f deg", deg); };
  const double elbow_deg = t.record.joint_samples(1).angle_rad(k) * 180.0 / std::numbers::pi;
  const double shoulder_deg = t.record.joint_samples(0).angle_rad(k) * 180.0 / std::numbers::pi;
  ASSERT_NE(readout(elbow_deg), readout(shoulder_deg));  // the check below tells the joints apart
  EXPECT_TRUE(std::regex_search(
      screen, std::regex("angle +" + std::regex_replace(readout(elbow_deg), std::regex("\\."), "\\."))))
      << readout(elbow_deg) << "\n"
      << screen;
  EXPECT_NE(screen.find(format("u_ilc      %.4f bar", t.record.joint_samples(1).u_ilc_bar(k))), std::string::npos)
      << screen;

  // The live strip follows the selection: the elbow's angle, not the shoulder's.
  f.key(key::kEscape);
  f.pump_for(0.5);
  const TickRecord& live = f.state().live;
  ASSERT_FALSE(f.state().strip.angle_deg.empty());
  EXPECT_NEAR(f.state().strip.angle_deg.back(), live.reading.joint[1].angle_rad * 180.0 / std::numbers::pi, 1.0);
  EXPECT_NEAR(f.state().strip.setpoint_deg.back(), live.joint(1).desired_rad * 180.0 / std::numbers::pi, 1e-9);
  f.key('j');
  EXPECT_NEAR(f.state().strip.angle_deg.back(), live.reading.joint[0].angle_rad * 180.0 / std::numbers::pi, 1.0);
  EXPECT_NEAR(f.state().strip.setpoint_deg.back(), live.joint(0).desired_rad * 180.0 / std::numbers::pi, 1e-9);
}

TEST(UiJoints, AGuardNamesTheJointAndTheChamberItFiredOn) {
  const Configuration c = arm2_config();
  TickRecord tick;
  tick.reading.joint_count = 2;
  for (JointReading& j : tick.reading.joint) j.chamber_bar = {1.2, 1.2};
  tick.reading.joint[1].angle_rad = 100.0 * std::numbers::pi / 180.0;
  EXPECT_EQ(fault_location(FaultCode::kAngleLimit, 1, tick, c),
            "joint 2 (elbow): angle 100.0 deg beyond its limit of 95 deg");
  Configuration own = c;
  own.safety.joint_angle_limit_deg[1] = 99.5;  // the elbow's own limit, not [safety] angle_limit_deg
  EXPECT_EQ(fault_location(FaultCode::kAngleLimit, 1, tick, own),
            "joint 2 (elbow): angle 100.0 deg beyond its limit of 99.5 deg");
  tick.reading.joint[1].angle_rad = 0.0;
  tick.reading.joint[0].chamber_bar[1] = 3.0;
  EXPECT_EQ(fault_location(FaultCode::kOverpressure, 0, tick, c),
            format("joint 1 (shoulder) chamber B: 3.000 bar above p_max plus the margin (%.3f bar)",
                   c.controller.p_max_bar + c.safety.pressure_margin_bar));
  EXPECT_EQ(fault_location(FaultCode::kSupplyLow, -1, tick, c), "");  // the supply is every joint's
  tick.reading.joint_count = 1;
  EXPECT_EQ(fault_location(FaultCode::kOverpressure, 0, tick, c), "");  // one joint: nothing to name
}

TEST(UiJoints, AJointsOwnAngleLimitFaultsTheConsoleNamingThatJointAndItsLimit) {
  Configuration config = arm2_config();
  // Below paper2's elbow (+-30 deg), so that the first trial crosses it. (A configuration file keeps
  // every joint's limit above [trajectory] max_abs_angle_deg: validate_configuration refuses this.)
  config.safety.joint_angle_limit_deg[1] = 25.0;
  Arm2Console a(config);
  ConsoleFixture& f = a.f;
  f.arm_valves();
  f.key('N');
  f.key(key::kBackspace);
  f.key(key::kBackspace);
  f.type("1");
  f.key(key::kEnter);
  ASSERT_TRUE(f.pump_until([&] { return !f.state().fault_view.where.empty(); }));
  EXPECT_EQ(f.state().fault, FaultCode::kAngleLimit);
  EXPECT_EQ(f.state().fault_view.joint, 1);
  const std::string& where = f.state().fault_view.where;
  EXPECT_TRUE(std::regex_match(
      where, std::regex("joint 2 \\(elbow\\): angle -?(2[5-9]|3[0-9])\\.[0-9] deg beyond its limit of 25 deg")))
      << where;
  const double shoulder_deg =
      f.state().fault_view.black_box.back().reading.joint[0].angle_rad * 180.0 / std::numbers::pi;
  EXPECT_LT(std::abs(shoulder_deg), 25.0) << "the shoulder stayed inside 25 deg";
  EXPECT_TRUE(f.logged("angle-limit fired on joint 2 (elbow)"));
  const std::string screen = screen_text(f.state());
  EXPECT_NE(screen.find("on joint 2 (elbow)"), std::string::npos) << screen;
}

TEST(UiJoints, AnEmergencyStopOnArm2ShowsTheSelectedJointsBlackBox) {
  Arm2Console a;
  ConsoleFixture& f = a.f;
  f.arm_valves();
  f.pump_for(1.0);
  f.key('j');
  f.key(' ');
  ASSERT_TRUE(f.pump_until(
      [&] { return f.state().engine_state == EngineState::kFault && !f.state().fault_view.black_box.empty(); }));
  EXPECT_EQ(f.state().screen, Screen::kFault);
  const std::string screen = screen_text(f.state());
  EXPECT_NE(screen.find("Last ticks before the fault, joint 2/2 elbow"), std::string::npos) << screen;
  EXPECT_EQ(f.state().fault_view.where, "");  // an operator's stop is no joint's
}

}  // namespace
}  // namespace bellows::ui
