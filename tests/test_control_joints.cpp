// The control scheme for J joints (engine/control/control_core, issue 14): each joint its own PID, pressure
// pair and set points, joint 1 computing exactly as the single-joint core; a reading of another joint
// count driving nothing; every joint's state resumed exactly; and the engine refusing trials whose
// correction or record does not fit the trajectory's joints, and faulting (never indexing beyond a
// reading) when the arm has another joint count than the trajectory.
#include <gtest/gtest.h>

#include <cmath>

#include "engine/control/control_core.hpp"
#include "tests/engine_fixture.hpp"
#include "tests/test_support.hpp"

namespace bellows {
namespace {

/// A reading that does not depend on the commands (the cores are compared open loop): every joint's
/// angle and chambers move with time, each joint differently.
SensorReading moving_reading(int joints, int tick, double tick_s) {
  const double t = tick * tick_s;
  SensorReading r;
  r.time_s = t;
  r.joint_count = joints;
  for (int j = 0; j < joints; ++j) {
    JointReading& joint = r.joint[static_cast<std::size_t>(j)];
    joint.angle_rad = 0.3 * std::sin((1.3 + 0.4 * j) * t + j);
    joint.chamber_bar = {1.15 + 0.1 * std::sin((2.0 + j) * t), 1.1 + 0.08 * std::cos((1.7 + j) * t)};
  }
  r.supply_bar = 3.0 + 0.01 * std::sin(5.0 * t);
  r.temperature_K = 293.15;
  return r;
}

/// The same reading with its joint `joint` alone, as a single-joint arm's.
SensorReading one_joint_of(const SensorReading& r, int joint) {
  SensorReading one = r;
  one.joint_count = 1;
  one.joint = {};
  one.joint[0] = r.joint[static_cast<std::size_t>(joint)];
  return one;
}

Trajectory one_joint_trajectory_of(const Trajectory& t, int joint) {
  return Trajectory{t.name, t.sample_time_s, {t.joint(joint)}};
}

void expect_same_columns(const Eigen::VectorXd& a, const Eigen::VectorXd& b, const char* what, int joint) {
  ASSERT_EQ(a.size(), b.size()) << what;
  for (Eigen::Index i = 0; i < a.size(); ++i) ASSERT_EQ(a(i), b(i)) << what << " of joint " << joint + 1 << " at " << i;
}

TEST(ControlJoints, EachJointOfTwoComputesExactlyAsASingleJointCoreOnItsOwnReadings) {
  const Configuration config;
  const TimingParameters& timing = config.timing;
  const Trajectory paper2 = library_trajectory("paper2", timing.sample_s());
  const int n = paper2.learning_samples();
  Eigen::MatrixXd correction(n, 2);
  for (int k = 0; k < n; ++k) correction.row(k) << 0.05 * std::sin(0.03 * k), -0.04 * std::cos(0.05 * k);
  const Eigen::VectorXd correction_1 = correction.col(0), correction_2 = correction.col(1);
  const Trajectory joint_1 = one_joint_trajectory_of(paper2, 0), joint_2 = one_joint_trajectory_of(paper2, 1);

  ControlCore both(config.controller, timing), alone_1(config.controller, timing), alone_2(config.controller, timing);
  TrialRecord record, record_1, record_2;
  both.hold(paper2.setpoint_rad(0));
  alone_1.hold(joint_1.joint(0)(0));
  alone_2.hold(joint_2.joint(0)(0));
  EXPECT_EQ(both.joints(), 2);
  const int hold_ticks = 41, trial_ticks = n * timing.ticks_per_sample + 23;  // holding, the trial, holding
  int saw_inlet = 0;
  for (int tick = 0; tick < hold_ticks + trial_ticks; ++tick) {
    if (tick == hold_ticks) {
      both.start_trial(paper2, correction, record);
      alone_1.start_trial(joint_1, correction_1, record_1);
      alone_2.start_trial(joint_2, correction_2, record_2);
    }
    const SensorReading r = moving_reading(2, tick, timing.tick_s);
    const ValveCommand c = both.tick(r), c1 = alone_1.tick(one_joint_of(r, 0)), c2 = alone_2.tick(one_joint_of(r, 1));
    ASSERT_EQ(c.joint_count, 2);
    for (int j = 0; j < 2; ++j) {
      const JointValves& single = (j == 0 ? c1 : c2).joint[0];
      ASSERT_EQ(c.joint[static_cast<std::size_t>(j)].inlet_duty, single.inlet_duty)
          << "joint " << j + 1 << " tick " << tick;
      ASSERT_EQ(c.joint[static_cast<std::size_t>(j)].outlet_duty, single.outlet_duty)
          << "joint " << j + 1 << " tick " << tick;
      if (single.inlet_duty[0] > 0.0) ++saw_inlet;
    }
    ASSERT_EQ(both.setpoints(1).a_bar, alone_2.setpoints().a_bar);
    ASSERT_EQ(both.desired_angle_rad(1), alone_2.desired_angle_rad());
  }
  EXPECT_GT(saw_inlet, 100) << "the valves must have worked";
  ASSERT_TRUE(record.complete);
  ASSERT_EQ(record.joint_count(), 2);
  EXPECT_FALSE(both.trial_running());
  for (int j = 0; j < 2; ++j) {
    const TrialRecord& single = j == 0 ? record_1 : record_2;
    const TrialSamples &s = record.joint_samples(j), &t = single.joint_samples(0);
    for (const auto& [a, b, what] : {std::tuple{&s.setpoint_rad, &t.setpoint_rad, "setpoint"},
                                     {&s.angle_rad, &t.angle_rad, "angle"},
                                     {&s.error_rad, &t.error_rad, "error"},
                                     {&s.u_ilc_bar, &t.u_ilc_bar, "u_ilc"},
                                     {&s.u_total_bar, &t.u_total_bar, "u_total"},
                                     {&s.setpoint_b_bar, &t.setpoint_b_bar, "p_B set"}}) {
      expect_same_columns(*a, *b, what, j);
    }
    const TrialTicks &u = record.joint_ticks(j), &v = single.joint_ticks(0);
    expect_same_columns(u.inlet_a, v.inlet_a, "inlet A", j);
    expect_same_columns(u.outlet_b, v.outlet_b, "outlet B", j);
    expect_same_columns(record.supply_bar, single.supply_bar, "supply", j);
    EXPECT_EQ(record.joint_rms_error_deg(j), single.rms_error_deg());
    EXPECT_GT(record.joint_rms_error_deg(j), 1.0) << "open loop, the readings do not follow the trajectory";
  }
  // The learning's view: one column per joint, joint 1's the single-joint error.
  const Eigen::MatrixXd errors = record.normalized_joint_errors();
  ASSERT_EQ(errors.rows(), n);
  ASSERT_EQ(errors.cols(), 2);
  EXPECT_EQ(errors.col(0), record.normalized_error());
  EXPECT_EQ(errors.col(1), record_2.normalized_error());
  EXPECT_EQ(record.joint_samples(0).u_ilc_bar.head(n), correction_1);
  EXPECT_EQ(record.joint_samples(1).u_ilc_bar.head(n), correction_2);
}

TEST(ControlJoints, AReadingOfAnotherJointCountDrivesNothingAndVentsEveryJoint) {
  const Configuration config;
  ControlCore core(config.controller, config.timing);
  core.hold(JointVector::Constant(2, 0.1));
  for (int tick = 0; tick < 9; ++tick) core.tick(moving_reading(2, tick, config.timing.tick_s));
  const ControlCore::State before = core.state();
  for (int joints : {1, 3, 0, -2, kMaxJoints + 5}) {
    SensorReading r = moving_reading(2, 9, config.timing.tick_s);
    r.joint_count = joints;
    const ValveCommand c = core.tick(r);
    EXPECT_EQ(c.joint_count, 2) << joints;
    EXPECT_TRUE(testing::vented(c)) << joints;
  }
  const ControlCore::State after = core.state();
  EXPECT_EQ(after.tick_in_sample, before.tick_in_sample) << "no controller ran";
  EXPECT_EQ(after.joints[1].pid.integral_s, before.joints[1].pid.integral_s);
  EXPECT_EQ(after.joints[1].pressure_a.count, before.joints[1].pressure_a.count);
}

TEST(ControlJoints, EveryJointsStateResumesExactlyAndJointOneKeepsItsFields) {
  const Configuration config;
  const TimingParameters& timing = config.timing;
  ControlCore first(config.controller, timing);
  JointVector hold(3);
  hold << 0.2, -0.1, 0.3;
  first.hold(hold);
  for (int tick = 0; tick < 37; ++tick) first.tick(moving_reading(3, tick, timing.tick_s));  // mid-sample
  const ControlCore::State saved = first.state();
  EXPECT_EQ(saved.joint_count, 3);
  EXPECT_EQ(saved.joints[0].hold_rad, 0.2);
  EXPECT_EQ(saved.joints[1].hold_rad, -0.1);
  EXPECT_EQ(saved.joints[2].hold_rad, 0.3);
  EXPECT_NE(saved.joints[2].pid.integral_s, 0.0);
  ControlCore resumed(config.controller, timing);
  resumed.set_state(saved);
  EXPECT_EQ(resumed.joints(), 3);
  for (int tick = 37; tick < 137; ++tick) {
    const SensorReading r = moving_reading(3, tick, timing.tick_s);
    const ValveCommand a = first.tick(r), b = resumed.tick(r);
    for (int j = 0; j < 3; ++j) {
      ASSERT_EQ(a.joint[static_cast<std::size_t>(j)].inlet_duty, b.joint[static_cast<std::size_t>(j)].inlet_duty)
          << tick;
      ASSERT_EQ(a.joint[static_cast<std::size_t>(j)].outlet_duty, b.joint[static_cast<std::size_t>(j)].outlet_duty)
          << tick;
    }
  }
  // A single-joint state (what every session saved so far holds) drives one joint.
  ControlCore::State single = saved;
  single.joint_count = 1;
  resumed.set_state(single);
  EXPECT_EQ(resumed.joints(), 1);
  EXPECT_EQ(resumed.state().joints[1].pid.integral_s, 0.0) << "joints not driven start fresh";
}

TEST(EngineJoints, ATwoJointTrajectoryOnAOneJointArmFaultsWhenArmedAndNeverDrivesIt) {
  testing::EngineFixture f;  // the single-joint simulated arm
  const Trajectory paper2 = library_trajectory("paper2", f.config.timing.sample_s());
  EXPECT_TRUE(f.core.send(EngineCommand::select_trajectory(paper2)));
  f.clock.step();
  EXPECT_EQ(f.core.joints(), 2);
  f.send(CommandKind::kArm);
  f.clock.step();
  EXPECT_EQ(f.core.state(), EngineState::kFault);
  EXPECT_EQ(f.core.fault(), FaultCode::kSensorOutOfRange);
  EXPECT_TRUE(testing::vented(f.snapshot().valves));
}

TEST(EngineJoints, RefusesATrialWhoseCorrectionOrRecordDoesNotFitItsTrajectorysJoints) {
  testing::EngineFixture f;
  f.send(CommandKind::kArm);  // no trajectory: one joint, where the arm is
  f.clock.step();
  ASSERT_EQ(f.core.state(), EngineState::kArmed);
  const Trajectory paper2 = library_trajectory("paper2", f.config.timing.sample_s());
  const int n = paper2.learning_samples();
  const Eigen::VectorXd one_joint = Eigen::VectorXd::Zero(n);
  const Eigen::MatrixXd one_column = Eigen::MatrixXd::Zero(n, 1), two_columns = Eigen::MatrixXd::Zero(n, 2);
  TrialRecord for_one, for_two;
  for_one.prepare(n, f.config.timing.ticks_per_sample);
  for_two.prepare(n, f.config.timing.ticks_per_sample, 2);
  struct Case {
    EngineCommand command;
    const char* refusal;
  };
  const Case cases[] = {
      {EngineCommand::start_trial(paper2, one_joint, for_two, 0, 1),
       "the trial's correction is not one column of N values per joint of its trajectory"},
      {EngineCommand::start_trial(paper2, one_column, for_two, 0, 2),
       "the trial's correction is not one column of N values per joint of its trajectory"},
      {EngineCommand::start_trial(paper2, two_columns, for_one, 0, 3),
       "the trial's record is not prepared for the joints of its trajectory"},
  };
  f.drain_events();
  for (const Case& c : cases) {
    EXPECT_TRUE(f.core.send(c.command));
    f.clock.step();
    const auto events = f.drain_events();
    ASSERT_EQ(events.size(), 1u) << c.refusal;
    EXPECT_EQ(events[0].kind, EventKind::kCommandRefused);
    EXPECT_STREQ(events[0].refusal, c.refusal);
    EXPECT_EQ(f.core.state(), EngineState::kArmed);
    EXPECT_EQ(f.core.joints(), 1) << "a refused trial selects nothing";
  }
  Trajectory uneven = paper2;
  uneven.joint(1).conservativeResize(n - 3);
  EXPECT_TRUE(f.core.send(EngineCommand::select_trajectory(uneven)));
  f.clock.step();
  const auto events = f.drain_events();
  ASSERT_EQ(events.size(), 1u);
  EXPECT_STREQ(events[0].refusal, "the trajectory's joints do not all have the same number of samples");
  EXPECT_EQ(f.core.state(), EngineState::kArmed);
}

}  // namespace
}  // namespace bellows
