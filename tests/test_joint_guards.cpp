// Every guard per joint (issue 14): each joint's own angle limit (`[arm_jointN] angle_limit_deg`,
// default `[safety] angle_limit_deg`) trips on its own joint only, and the fault names that joint
// (the kFault event's fault_joint, the black box's fault tick). The engine drives the simulated arm2
// chain through paper2 on a simulated clock: the shoulder moves +-20 deg, the elbow +-30 deg.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <optional>

#include "devices/simulated_arm_chain.hpp"
#include "engine/config/configuration.hpp"
#include "engine/rt/engine_core.hpp"
#include "engine/rt/engine_driver.hpp"
#include "engine/model/pneumatic_arm_chain_parameters.hpp"

namespace bellows {
namespace {

constexpr double kDegPerRad = 180.0 / std::numbers::pi;

/// arm2 driven by an engine whose safety is `safety`, paper2 selected and armed.
struct GuardedArm2 {
  explicit GuardedArm2(const SafetyParameters& safety)
      : arm(pneumatic_chain_of(config.plant, ArmParameters{"arm2"}), 1),
        core(arm, config.controller, config.timing, safety),
        clock(core, arm),
        paper2(library_trajectory("paper2", config.timing.sample_s())) {
    EXPECT_TRUE(core.send(EngineCommand::select_trajectory(paper2)));
    EXPECT_TRUE(core.send(EngineCommand::of(CommandKind::kArm)));
    clock.step(std::lround(2.0 / config.timing.tick_s));  // holding (0, 0): the sag taken up
  }

  /// One feedback-only trial of paper2; the kFault event if a guard fired.
  std::optional<EngineEvent> trial() {
    record.prepare(paper2.learning_samples(), config.timing.ticks_per_sample, paper2.joints());
    correction = Eigen::MatrixXd::Zero(paper2.learning_samples(), paper2.joints());
    EXPECT_TRUE(core.send(EngineCommand::start_trial(paper2, correction, record, 0, 1)));
    clock.step(static_cast<long>(paper2.learning_samples()) * config.timing.ticks_per_sample + 2);
    std::optional<EngineEvent> fault;
    EngineEvent event;
    while (core.poll_event(event)) {
      if (event.kind == EventKind::kFault) fault = event;
    }
    return fault;
  }

  /// The largest |angle| joint `joint` reached in the trial's samples (deg).
  double peak_deg(int joint) const { return record.joint_samples(joint).angle_rad.cwiseAbs().maxCoeff() * kDegPerRad; }

  Configuration config;
  SimulatedArmChain arm;
  EngineCore core;
  SimulatedClock clock;
  Trajectory paper2;
  TrialRecord record;
  Eigen::MatrixXd correction;
};

TEST(JointGuards, EachJointsLimitDefaultsToTheSafetyLimit) {
  SafetyParameters limits;
  for (int j = 0; j < kMaxJoints; ++j) EXPECT_EQ(limits.angle_limit_deg_of(j), limits.angle_limit_deg);
  limits.joint_angle_limit_deg[1] = 40.0;
  EXPECT_EQ(limits.angle_limit_deg_of(0), limits.angle_limit_deg);
  EXPECT_EQ(limits.angle_limit_deg_of(1), 40.0);
}

TEST(JointGuards, AJointsOwnLimitTripsOnThatJointOnlyAndTheGuardNamesIt) {
  for (int limited = 0; limited < kMaxJoints; ++limited) {
    SafetyParameters limits;
    limits.joint_angle_limit_deg[static_cast<std::size_t>(limited)] = 30.0;
    GuardInputs in;
    in.joint_count = kMaxJoints;
    for (int moved = 0; moved < kMaxJoints; ++moved) {
      SensorReading r;
      r.joint_count = kMaxJoints;
      r.supply_bar = 4.0;
      for (JointReading& j : r.joint) j.chamber_bar = {1.2, 1.2};
      r.joint[static_cast<std::size_t>(moved)].angle_rad = 40.0 / kDegPerRad;  // beyond 30, inside 95
      const GuardFault fired = find_guard_fault(r, in, limits);
      if (moved == limited) {
        EXPECT_EQ(fired.code, FaultCode::kAngleLimit) << "joint " << limited + 1;
        EXPECT_EQ(fired.joint, limited);
      } else {
        EXPECT_EQ(fired.code, FaultCode::kNone)
            << "joint " << moved + 1 << " at 40 deg tripped joint " << limited + 1 << "'s limit";
      }
      r.joint[static_cast<std::size_t>(moved)].angle_rad = 96.0 / kDegPerRad;  // beyond [safety] angle_limit_deg
      EXPECT_EQ(find_guard_fault(r, in, limits).joint, moved);
    }
  }
}

TEST(JointGuards, EveryChamberOfEveryJointIsGuardedAndNamed) {
  const SafetyParameters limits;
  GuardInputs in;
  in.joint_count = kMaxJoints;
  for (int joint = 0; joint < kMaxJoints; ++joint) {
    for (int chamber = 0; chamber < kActuatorCount; ++chamber) {
      SensorReading r;
      r.joint_count = kMaxJoints;
      r.supply_bar = 4.0;
      for (JointReading& j : r.joint) j.chamber_bar = {1.2, 1.2};
      r.joint[static_cast<std::size_t>(joint)].chamber_bar[static_cast<std::size_t>(chamber)] = 3.0;
      const GuardFault fired = find_guard_fault(r, in, limits);
      EXPECT_EQ(fired.code, FaultCode::kOverpressure) << "joint " << joint + 1 << " chamber " << chamber;
      EXPECT_EQ(fired.joint, joint);
    }
  }
  SensorReading low;
  low.joint_count = 1;
  low.supply_bar = 1.0;
  low.joint[0].chamber_bar = {1.2, 1.2};
  EXPECT_EQ(find_guard_fault(low, GuardInputs{}, limits).code, FaultCode::kSupplyLow);
  EXPECT_EQ(find_guard_fault(low, GuardInputs{}, limits).joint, -1) << "the supply is no joint's";
}

TEST(JointGuards, TheShouldersLimitFaultsTheEngineNamingTheShoulder) {
  SafetyParameters safety;
  safety.joint_angle_limit_deg[0] = 15.0;  // paper2's shoulder goes to +-20 deg
  GuardedArm2 a(safety);
  const std::optional<EngineEvent> fault = a.trial();
  ASSERT_TRUE(fault.has_value());
  EXPECT_EQ(fault->fault, FaultCode::kAngleLimit);
  EXPECT_EQ(fault->fault_joint, 0);
  EXPECT_EQ(a.core.state(), EngineState::kFault);
  ASSERT_TRUE(a.core.black_box().frozen());
  const TickRecord last = a.core.black_box().copy_frozen().back();
  EXPECT_EQ(last.fault, FaultCode::kAngleLimit);
  EXPECT_EQ(last.fault_joint, 0);
  EXPECT_GT(std::abs(last.reading.joint[0].angle_rad) * kDegPerRad, 15.0);
  EXPECT_LT(std::abs(last.reading.joint[1].angle_rad) * kDegPerRad, safety.angle_limit_deg);
  // A reset forgets the joint with the fault.
  EXPECT_TRUE(a.core.send(EngineCommand::of(CommandKind::kReset)));
  a.clock.step();
  TickRecord now;
  ASSERT_TRUE(a.core.read_snapshot(now));
  EXPECT_EQ(now.fault, FaultCode::kNone);
  EXPECT_EQ(now.fault_joint, -1);
}

TEST(JointGuards, TheElbowsLimitFaultsTheEngineNamingTheElbow) {
  SafetyParameters safety;
  safety.joint_angle_limit_deg[1] = 25.0;  // paper2's elbow goes to +-30 deg, the shoulder to +-20
  GuardedArm2 a(safety);
  const std::optional<EngineEvent> fault = a.trial();
  ASSERT_TRUE(fault.has_value());
  EXPECT_EQ(fault->fault, FaultCode::kAngleLimit);
  EXPECT_EQ(fault->fault_joint, 1);
  const TickRecord last = a.core.black_box().copy_frozen().back();
  EXPECT_GT(std::abs(last.reading.joint[1].angle_rad) * kDegPerRad, 25.0);
}

TEST(JointGuards, AnotherJointBeyondAJointsLimitDoesNotTripIt) {
  SafetyParameters safety;
  safety.joint_angle_limit_deg[0] = 28.0;  // the shoulder's: the elbow goes beyond it, the shoulder not
  GuardedArm2 a(safety);
  const std::optional<EngineEvent> fault = a.trial();
  EXPECT_FALSE(fault.has_value()) << fault_name(fault->fault) << " on joint " << fault->fault_joint + 1;
  EXPECT_TRUE(a.record.complete);
  EXPECT_GT(a.peak_deg(1), 28.0) << "the elbow must go beyond the shoulder's limit for this test to mean anything";
  EXPECT_LT(a.peak_deg(0), 28.0);
}

}  // namespace
}  // namespace bellows
