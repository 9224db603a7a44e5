// The simulated J-joint arm as a device (devices/simulated_arm_chain): with one joint it reads as the
// single-joint simulated arm (the tolerance of test_pneumatic_arm_chain's same comparison); with two
// its readings carry both joints, each joint's valves drive that joint's chambers, the mapping loses
// nothing of the chain's own readings, and a command for another joint count vents every joint.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "devices/simulated_arm.hpp"
#include "devices/simulated_arm_chain.hpp"
#include "tests/test_support.hpp"

namespace bellows {
namespace {

constexpr double kChainTick_s = 0.005;

/// Valves like a pressure controller's, per joint: an inlet on one chamber, an outlet on the other,
/// moving with time (several valve edges in every PWM period).
ValveCommand swinging_valves(int joints, double t) {
  ValveCommand c;
  c.joint_count = joints;
  for (int j = 0; j < joints; ++j) {
    const double u = 0.5 * std::sin((3.0 + j) * t) + 0.3 * std::sin((11.0 + 2 * j) * t);
    JointValves& v = c.joint[static_cast<std::size_t>(j)];
    v.inlet_duty = {std::max(0.0, u), std::max(0.0, -u)};
    v.outlet_duty = {std::max(0.0, -0.8 * u), std::max(0.0, 0.8 * u)};
  }
  return c;
}

TEST(SimulatedArmChain, OneJointReadsAsTheSingleJointSimulatedArm) {
  const PlantParameters plant;
  SimulatedArm single(plant, 11);
  SimulatedArmChain chain(pneumatic_chain_of(plant), 11);
  Device& a_device = single;
  Device& b_device = chain;
  ASSERT_EQ(chain.joints(), 1);
  EXPECT_TRUE(b_device.time_follows_ticks());
  double largest_angle = 0.0;
  int readings_differing = 0;
  for (int tick = 0; tick < 800; ++tick) {  // 4 s: fills, vents, swings far
    const SensorReading a = a_device.read_sensors(), b = b_device.read_sensors();
    ASSERT_EQ(b.joint_count, 1);
    ASSERT_EQ(a.time_s, b.time_s);
    ASSERT_EQ(a.supply_bar, b.supply_bar);  // the same noise, drawn in the same order
    ASSERT_EQ(a.temperature_K, b.temperature_K);
    for (int c = 0; c < 2; ++c)
      EXPECT_NEAR(a.joint[0].chamber_bar[c], b.joint[0].chamber_bar[c], 1e-9) << "tick " << tick;
    if (a.joint[0].angle_rad != b.joint[0].angle_rad) ++readings_differing;  // only on a quantization edge
    EXPECT_NEAR(a.joint[0].angle_rad, b.joint[0].angle_rad, 0.1 * std::numbers::pi / 180.0 + 1e-12);
    largest_angle = std::max(largest_angle, std::abs(a.joint[0].angle_rad));
    const ValveCommand command = swinging_valves(1, a.time_s);
    a_device.write_valves(command);
    b_device.write_valves(command);
    a_device.advance(kChainTick_s);
    b_device.advance(kChainTick_s);
  }
  EXPECT_GT(largest_angle, 60.0 * std::numbers::pi / 180.0) << "the drive must move the arm far";
  EXPECT_LE(readings_differing, 2);
}

TEST(SimulatedArmChain, TwoJointReadingsCarryBothJointsExactlyAsTheChainReadsThem) {
  const PneumaticChainParameters arm2 = pneumatic_chain_preset("arm2");
  SimulatedArmChain device(arm2, 5);
  PneumaticArmChain reference(arm2, 5);
  std::vector<BellowsDuties> duties(2);
  for (int tick = 0; tick < 400; ++tick) {
    const SensorReading r = device.read_sensors();
    const PneumaticArmChain::Reading s = reference.read_sensors();
    ASSERT_EQ(r.joint_count, 2);
    ASSERT_EQ(r.time_s, s.time_s);
    for (int j = 0; j < 2; ++j) {
      ASSERT_EQ(r.joint[static_cast<std::size_t>(j)].angle_rad, s.angle_rad(j)) << tick;
      ASSERT_EQ(r.joint[static_cast<std::size_t>(j)].chamber_bar, s.chamber_bar[static_cast<std::size_t>(j)]) << tick;
    }
    for (std::size_t j = 2; j < kMaxJoints; ++j) EXPECT_EQ(r.joint[j].angle_rad, 0.0) << "beyond joint_count: nothing";
    ASSERT_EQ(r.supply_bar, s.supply_bar);
    const ValveCommand command = swinging_valves(2, r.time_s);
    for (int j = 0; j < 2; ++j) {
      const JointValves& v = command.joint[static_cast<std::size_t>(j)];
      duties[static_cast<std::size_t>(j)] = {v.inlet_duty, v.outlet_duty};
    }
    device.write_valves(command);
    reference.write_valves(duties);
    device.advance(kChainTick_s);
    reference.advance(kChainTick_s);
  }
  EXPECT_GT(std::abs(device.read_sensors().joint[1].angle_rad - device.read_sensors().joint[0].angle_rad), 0.0);
}

TEST(SimulatedArmChain, EachJointsValvesDriveItsOwnChambersAndACommandForAnotherArmVentsAll) {
  SimulatedArmChain device(pneumatic_chain_preset("arm2"), 1);
  const double shoulder_kg = device.chain().air_mass_kg(0), elbow_kg = device.chain().air_mass_kg(1);
  ValveCommand elbow_a;
  elbow_a.joint_count = 2;
  elbow_a.joint[1].inlet_duty = {0.6, 0.0};  // the elbow's chamber A fills; every other valve closed
  for (int tick = 0; tick < 40; ++tick) {
    device.write_valves(elbow_a);
    device.advance(kChainTick_s);
  }
  EXPECT_NEAR(device.chain().air_mass_kg(0) / shoulder_kg, 1.0, 1e-9) << "the shoulder's air stays, closed";
  EXPECT_GT(device.chain().air_mass_kg(1) / elbow_kg, 1.1) << "the elbow's chamber A filled";
  EXPECT_GT(device.read_sensors().joint[1].chamber_bar[0], device.read_sensors().joint[1].chamber_bar[1] + 0.1);

  ValveCommand one_joint = elbow_a;
  one_joint.joint_count = 1;
  one_joint.joint[0].inlet_duty = {1.0, 1.0};
  device.write_valves(one_joint);
  const PneumaticArmChain::State vented = device.chain().state();
  for (int j = 0; j < 2; ++j) {
    const BellowsDuties& d = vented.duties[static_cast<std::size_t>(j)];
    EXPECT_EQ(d.inlet, (std::array<double, 2>{0.0, 0.0})) << "joint " << j + 1;
    EXPECT_EQ(d.outlet, (std::array<double, 2>{1.0, 1.0})) << "joint " << j + 1;
  }
  device.write_valves(elbow_a);
  device.vent();
  EXPECT_EQ(device.chain().state().duties[1].outlet, (std::array<double, 2>{1.0, 1.0}));
}

}  // namespace
}  // namespace bellows
