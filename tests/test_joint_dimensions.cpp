// The basic real-time types sized by the joint count (issue 14, "dimensions first"): readings and
// commands of up to kMaxJoints joints, the guards joint by joint, and the one-joint devices refusing
// (venting) a command meant for an arm of another joint count.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <numbers>

#include "devices/simulated_arm.hpp"
#include "engine/control/device.hpp"
#include "engine/control/safety.hpp"

namespace bellows {
namespace {

constexpr double kDegree = std::numbers::pi / 180.0;

/// A plausible reading of `joints` joints at rest: every guard passes.
SensorReading calm_reading(int joints) {
  SensorReading r;
  r.time_s = 1.0;
  r.joint_count = joints;
  for (JointReading& j : r.joint) j.chamber_bar = {1.2, 1.2};
  r.supply_bar = 6.0;
  r.temperature_K = 293.0;
  return r;
}

GuardInputs guard_inputs_for(int joints) {
  GuardInputs in;
  in.joint_count = joints;
  return in;
}

TEST(JointDimensions, OneJointIsTheDefaultAndVentedVentsEveryJoint) {
  EXPECT_EQ(SensorReading{}.joint_count, 1);
  const ValveCommand held;
  EXPECT_EQ(held.joint_count, 1);
  for (const JointValves& j : held.joint) {
    EXPECT_EQ(j.inlet_duty, (std::array<double, 2>{0.0, 0.0}));
    EXPECT_EQ(j.outlet_duty, (std::array<double, 2>{0.0, 0.0})) << "default: every valve closed";
  }
  for (int joints = 1; joints <= kMaxJoints; ++joints) {
    const ValveCommand vented = ValveCommand::vented(joints);
    EXPECT_EQ(vented.joint_count, joints);
    for (const JointValves& j : vented.joint) {  // beyond joint_count too
      EXPECT_EQ(j.inlet_duty, (std::array<double, 2>{0.0, 0.0}));
      EXPECT_EQ(j.outlet_duty, (std::array<double, 2>{1.0, 1.0}));
    }
  }
  EXPECT_EQ(ValveCommand::vented().joint_count, 1);
  EXPECT_FALSE(valid_joint_count(0));
  EXPECT_TRUE(valid_joint_count(kMaxJoints));
  EXPECT_FALSE(valid_joint_count(kMaxJoints + 1));
}

TEST(JointDimensions, EveryGuardWatchesEveryJoint) {
  const SafetyParameters limits;
  for (int joints = 1; joints <= kMaxJoints; ++joints) {
    const GuardInputs in = guard_inputs_for(joints);
    EXPECT_EQ(check_guards(calm_reading(joints), in, limits), FaultCode::kNone) << joints;
    const std::size_t last = static_cast<std::size_t>(joints - 1);  // the joint furthest out
    SensorReading r = calm_reading(joints);
    r.joint[last].angle_rad = (limits.angle_limit_deg + 1.0) * kDegree;
    EXPECT_EQ(check_guards(r, in, limits), FaultCode::kAngleLimit) << joints;
    r = calm_reading(joints);
    r.joint[last].chamber_bar[1] = in.p_max_bar + limits.pressure_margin_bar + 0.01;
    EXPECT_EQ(check_guards(r, in, limits), FaultCode::kOverpressure) << joints;
    r = calm_reading(joints);
    r.joint[last].chamber_bar[0] = std::numeric_limits<double>::quiet_NaN();
    EXPECT_EQ(check_guards(r, in, limits), FaultCode::kSensorNotANumber) << joints;
    r = calm_reading(joints);
    r.joint[last].angle_rad = (limits.sensor_max_angle_deg + 1.0) * kDegree;
    EXPECT_EQ(check_guards(r, in, limits), FaultCode::kSensorOutOfRange) << joints;
  }
  // Joints beyond joint_count are not read: whatever they hold faults nothing.
  SensorReading r = calm_reading(1);
  r.joint[1].angle_rad = std::numeric_limits<double>::quiet_NaN();
  r.joint[2].chamber_bar[0] = 99.0;
  EXPECT_EQ(check_guards(r, guard_inputs_for(1), limits), FaultCode::kNone);
}

TEST(JointDimensions, TheMostBasicFaultWinsWhicheverJointShowsIt) {
  const SafetyParameters limits;
  SensorReading r = calm_reading(3);
  r.joint[0].angle_rad = (limits.angle_limit_deg + 1.0) * kDegree;  // joint 1 beyond its limit
  r.joint[2].angle_rad = std::numeric_limits<double>::quiet_NaN();  // joint 3's encoder broken
  EXPECT_EQ(check_guards(r, guard_inputs_for(3), limits), FaultCode::kSensorNotANumber);
}

TEST(JointDimensions, AReadingForAnotherJointCountIsImplausible) {
  const SafetyParameters limits;
  EXPECT_EQ(check_guards(calm_reading(2), guard_inputs_for(1), limits), FaultCode::kSensorOutOfRange)
      << "an engine of one joint cannot guard a two-joint arm";
  EXPECT_EQ(check_guards(calm_reading(1), guard_inputs_for(2), limits), FaultCode::kSensorOutOfRange);
  for (int bad : {0, -1, kMaxJoints + 1}) {
    SensorReading r = calm_reading(1);
    r.joint_count = bad;
    GuardInputs in = guard_inputs_for(bad);
    EXPECT_EQ(check_guards(r, in, limits), FaultCode::kSensorOutOfRange) << bad;
  }
}

TEST(JointDimensions, TheSimulatedArmHasOneJointAndVentsACommandForAnother) {
  SimulatedArm arm(PlantParameters{}, 3);
  EXPECT_EQ(arm.read_sensors().joint_count, 1);
  ValveCommand fill;
  fill.joint[0].inlet_duty = {0.6, 0.0};
  fill.joint[0].outlet_duty = {0.0, 0.3};
  arm.write_valves(fill);
  EXPECT_EQ(arm.state().command.inlet_duty[0], 0.6);
  EXPECT_EQ(arm.state().command.outlet_duty[1], 0.3);
  ValveCommand two_joints = fill;
  two_joints.joint_count = 2;
  arm.write_valves(two_joints);
  EXPECT_EQ(arm.state().command.inlet_duty, (std::array<double, 2>{0.0, 0.0}));
  EXPECT_EQ(arm.state().command.outlet_duty, (std::array<double, 2>{1.0, 1.0})) << "meant for another arm: vented";
  EXPECT_EQ(single_joint_valves(fill).inlet_duty[0], 0.6);
}

}  // namespace
}  // namespace bellows
