// The simulated J-joint arm with its bellows (engine/model/pneumatic_arm_chain, ../shared/spec/multi-joint.md):
// one joint without gravity is the single-joint simulated arm, the presets' bellows, each joint's gas
// law with its own angle-dependent volumes, gravity on the chain, determinism, bit-for-bit resuming,
// refused commands and parameters, and an allocation-free step. Its own executable: it counts
// allocations (tests/allocation_counter.hpp replaces operator new).
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <vector>

#include "devices/simulated_arm.hpp"
#include "engine/base/errors.hpp"
#include "engine/model/pneumatic_arm_chain.hpp"
#include "tests/allocation_counter.hpp"

namespace bellows {
namespace {

constexpr double kTick_s = 0.005;

/// A drive like a pressure controller's: per joint an inlet on one chamber and an outlet on the
/// other, duties moving with time (several valve edges in every PWM period).
BellowsDuties drive(int joint, double t) {
  const double u = 0.5 * std::sin((3.0 + joint) * t) + 0.3 * std::sin((11.0 + 2 * joint) * t);
  BellowsDuties d;
  d.inlet = {std::max(0.0, u), std::max(0.0, -u)};
  d.outlet = {std::max(0.0, -0.8 * u), std::max(0.0, 0.8 * u)};
  return d;
}

std::span<const BellowsDuties> commands(std::vector<BellowsDuties>& duties, double t) {
  for (std::size_t i = 0; i < duties.size(); ++i) duties[i] = drive(static_cast<int>(i), t);
  return duties;
}

/// Drives `arm` for `ticks` ticks; returns every reading's values in order.
std::vector<double> run(PneumaticArmChain& arm, int ticks) {
  std::vector<double> values;
  std::vector<BellowsDuties> duties(static_cast<std::size_t>(arm.joints()));
  for (int tick = 0; tick < ticks; ++tick) {
    const PneumaticArmChain::Reading r = arm.read_sensors();
    for (int i = 0; i < arm.joints(); ++i) {
      values.push_back(r.angle_rad(i));
      values.push_back(r.chamber_bar[static_cast<std::size_t>(i)][0]);
      values.push_back(r.chamber_bar[static_cast<std::size_t>(i)][1]);
    }
    values.push_back(r.supply_bar);
    arm.write_valves(commands(duties, r.time_s));
    arm.advance(kTick_s);
  }
  return values;
}

TEST(PneumaticArmChain, OneJointWithoutGravityIsTheSingleJointSimulatedArm) {
  const PlantParameters plant;
  SimulatedArm single(plant, 11);
  PneumaticArmChain chain(pneumatic_chain_of(plant), 11);
  ASSERT_EQ(chain.joints(), 1);
  std::vector<BellowsDuties> duties(1);
  double largest_angle = 0.0, largest_pressure_difference_bar = 0.0;
  int readings_differing = 0;
  for (int tick = 0; tick < 800; ++tick) {  // 4 s: fills, vents, swings beyond 60 deg
    const SensorReading a = single.read_sensors();
    const PneumaticArmChain::Reading b = chain.read_sensors();
    ASSERT_EQ(a.time_s, b.time_s);
    ASSERT_EQ(a.supply_bar, b.supply_bar);  // the same noise, drawn in the same order
    for (int c = 0; c < 2; ++c) EXPECT_NEAR(a.joint[0].chamber_bar[c], b.chamber_bar[0][c], 1e-9) << "tick " << tick;
    if (a.joint[0].angle_rad != b.angle_rad(0))
      ++readings_differing;  // at most where the angle sits on a quantization edge
    EXPECT_NEAR(a.joint[0].angle_rad, b.angle_rad(0), 0.1 * std::numbers::pi / 180.0 + 1e-12);
    const SimulatedArm::State s = single.state();
    const PneumaticArmChain::State t = chain.state();
    ASSERT_NEAR(s.angle_rad, t.angle_rad(0), 1e-10) << "tick " << tick;
    ASSERT_NEAR(s.angular_velocity_rad_per_s, t.velocity_rad_per_s(0), 1e-8) << "tick " << tick;
    ASSERT_NEAR(s.creep_rad, t.creep_rad(0), 1e-10);
    for (int c = 0; c < 2; ++c) ASSERT_NEAR(s.chamber_Pa[c], t.chamber_Pa[0][c], 1e-4) << "tick " << tick;
    largest_angle = std::max(largest_angle, std::abs(s.angle_rad));
    largest_pressure_difference_bar =
        std::max(largest_pressure_difference_bar, std::abs(s.chamber_Pa[0] - s.chamber_Pa[1]) / 1e5);
    const BellowsDuties d = drive(0, a.time_s);
    ValveCommand command;
    command.joint[0].inlet_duty = d.inlet;
    command.joint[0].outlet_duty = d.outlet;
    single.write_valves(command);
    chain.write_valves(commands(duties, b.time_s));
    single.advance(kTick_s);
    chain.advance(kTick_s);
  }
  EXPECT_GT(largest_angle, 60.0 * std::numbers::pi / 180.0) << "the drive must move the arm far";
  EXPECT_GT(largest_pressure_difference_bar, 0.15);
  EXPECT_LE(readings_differing, 2);
}

TEST(PneumaticArmChain, PresetsGiveTheShoulderTwiceTheBellowsAndTheValves) {
  for (const char* preset : {"arm2", "arm3"}) {
    const PneumaticChainParameters p = pneumatic_chain_preset(preset);
    EXPECT_EQ(p.chain.joints, preset == std::string("arm2") ? 2 : 3);
    EXPECT_EQ(p.bellows[0].volume_l, 0.9) << preset;
    EXPECT_EQ(p.bellows[0].valve_conductance_m3_per_sPa, 6.0e-9) << preset;
    for (int i = 1; i < p.chain.joints; ++i) {
      EXPECT_EQ(p.bellows[static_cast<std::size_t>(i)].volume_l, 0.45) << preset << " joint " << i + 1;
      EXPECT_EQ(p.bellows[static_cast<std::size_t>(i)].valve_conductance_m3_per_sPa, 3.0e-9);
      EXPECT_EQ(p.bellows[static_cast<std::size_t>(i)].volume_gain_per_rad, 0.35);
    }
    EXPECT_EQ(p.supply_bar, 3.0);
    EXPECT_EQ(p.chain.integration_step_s, 1e-4);
  }
  // The shoulder takes twice the air of the elbow for the same duty (twice the conductance).
  PneumaticArmChain arm(pneumatic_chain_preset("arm2"), 1);
  const double shoulder_before = arm.air_mass_kg(0), elbow_before = arm.air_mass_kg(1);
  std::vector<BellowsDuties> duties(2, BellowsDuties{{0.5, 0.0}, {0.0, 0.0}});
  arm.write_valves(duties);
  arm.advance(kTick_s);
  const double shoulder_gain = arm.air_mass_kg(0) - shoulder_before, elbow_gain = arm.air_mass_kg(1) - elbow_before;
  EXPECT_NEAR(shoulder_gain / elbow_gain, 2.0, 0.01);
  try {
    pneumatic_chain_preset("arm5");
    FAIL() << "an unknown preset must be refused";
  } catch (const InputError& e) {
    EXPECT_STREQ(e.what(), "unknown arm preset 'arm5' (known: arm2, arm3)");
  }
}

TEST(PneumaticArmChain, TheConfigurationsArmPresetChoosesTheChainWithThePlantsSharedSettings) {
  PlantParameters plant;
  plant.supply_bar = 2.5;
  plant.pressure_noise_bar = 1e-3;
  plant.integration_step_s = 5e-5;
  const PneumaticChainParameters one = pneumatic_chain_of(plant, ArmParameters{});
  EXPECT_EQ(one.chain.joints, 1);  // absent: the single joint
  EXPECT_FALSE(one.chain.gravity);
  const PneumaticChainParameters arm3 = pneumatic_chain_of(plant, ArmParameters{"arm3"});
  EXPECT_EQ(arm3.chain.joints, 3);
  EXPECT_TRUE(arm3.chain.gravity);
  EXPECT_EQ(arm3.bellows[0].volume_l, 0.9);
  EXPECT_EQ(arm3.chain.links[2].kappa_rad_per_bar, 7.91);
  EXPECT_EQ(arm3.supply_bar, 2.5);
  EXPECT_EQ(arm3.pressure_noise_bar, 1e-3);
  EXPECT_EQ(arm3.chain.integration_step_s, 5e-5);
  EXPECT_THROW(pneumatic_chain_of(plant, ArmParameters{"arm9"}), InputError);
}

TEST(PneumaticArmChain, ClosedValvesKeepEachJointsAirWhileTheChainSwingsAndItsVolumesFollowItsOwnAngle) {
  PneumaticArmChain arm(pneumatic_chain_preset("arm3"), 1);
  PneumaticArmChain::State s = arm.state();
  s.chamber_Pa = {{{1.3e5, 1.1e5}, {1.05e5, 1.25e5}, {1.2e5, 1.2e5}}};
  arm.set_state(s);
  std::vector<BellowsDuties> closed(3);  // every valve closed
  arm.write_valves(closed);
  std::array<double, 3> mass{};
  for (int i = 0; i < 3; ++i) mass[static_cast<std::size_t>(i)] = arm.air_mass_kg(i);
  double largest_swing = 0.0;
  for (int tick = 0; tick < 200; ++tick) {  // 1 s: the arm falls and swings, coupled
    arm.advance(kTick_s);
    largest_swing = std::max(largest_swing, arm.state().angle_rad.cwiseAbs().maxCoeff());
    for (int i = 0; i < 3; ++i)
      ASSERT_NEAR(arm.air_mass_kg(i) / mass[static_cast<std::size_t>(i)], 1.0, 1e-9) << "joint " << i + 1;
    arm.write_valves(closed);
  }
  EXPECT_GT(largest_swing, 0.1);
  // Each joint's chambers follow its own angle: V = V0 (1 +- beta q_i), the shoulder's V0 0.9 L.
  const PneumaticArmChain::State end = arm.state();
  for (int i = 0; i < 3; ++i) {
    const double v0 = i == 0 ? 0.9e-3 : 0.45e-3, q = end.angle_rad(i);
    EXPECT_NEAR(arm.chamber_volume_m3(i, 0), v0 * (1.0 + 0.35 * q), 1e-15);
    EXPECT_NEAR(arm.chamber_volume_m3(i, 1), v0 * (1.0 - 0.35 * q), 1e-15);
    // the gas law with the joint's own volumes: p V constant for closed chambers
    EXPECT_NEAR(end.chamber_Pa[static_cast<std::size_t>(i)][0] * arm.chamber_volume_m3(i, 0),
                s.chamber_Pa[static_cast<std::size_t>(i)][0] * v0,
                1e-9 * s.chamber_Pa[static_cast<std::size_t>(i)][0] * v0);
  }
}

TEST(PneumaticArmChain, GravityPullsTheVentedArmDownAndHoldingPressuresHoldIt) {
  PneumaticArmChain vented(pneumatic_chain_preset("arm2"), 1);
  for (int tick = 0; tick < 40; ++tick) vented.advance(kTick_s);
  EXPECT_LT(vented.state().angle_rad(0), -0.05) << "the shoulder sags under the arm's weight";
  // Chambers pressurized to the chain's holding pressure differences, valves closed: it stays.
  PneumaticArmChain held(pneumatic_chain_preset("arm2"), 1);
  PneumaticArmChain::State s = held.state();
  const JointVector hold = held.mechanics().holding_pressure_bar(JointVector::Zero(2));
  for (int i = 0; i < 2; ++i)
    s.chamber_Pa[static_cast<std::size_t>(i)] = {1.2e5 + 0.5e5 * hold(i), 1.2e5 - 0.5e5 * hold(i)};
  held.set_state(s);
  std::vector<BellowsDuties> closed(2);
  held.write_valves(closed);
  for (int tick = 0; tick < 40; ++tick) held.advance(kTick_s);
  EXPECT_LT(held.state().angle_rad.cwiseAbs().maxCoeff(), 2e-3);
}

TEST(PneumaticArmChain, DeterministicForASeedAndAResumedRunContinuesBitForBit) {
  const PneumaticChainParameters arm3 = pneumatic_chain_preset("arm3");
  PneumaticArmChain a(arm3, 7), b(arm3, 7), c(arm3, 8);
  const std::vector<double> first = run(a, 300);
  EXPECT_EQ(first, run(b, 300));
  EXPECT_NE(first, run(c, 300));  // another seed, other noise
  // The state mid-run written into another arm (another seed): it continues exactly.
  const PneumaticArmChain::State middle = a.state();
  PneumaticArmChain resumed(arm3, 99);
  resumed.set_state(middle);
  const std::vector<double> rest = run(a, 300);
  EXPECT_EQ(rest, run(resumed, 300));
  EXPECT_EQ(a.state().angle_rad, resumed.state().angle_rad);
  EXPECT_EQ(a.state().chamber_Pa, resumed.state().chamber_Pa);
  EXPECT_GT(a.state().angle_rad.cwiseAbs().maxCoeff(), 0.05);  // it moved
}

TEST(PneumaticArmChain, CommandsAreClampedAndMisSizedOnesRefused) {
  PneumaticArmChain arm(pneumatic_chain_preset("arm2"), 1);
  std::vector<BellowsDuties> duties(2);
  duties[0] = {{1.7, std::nan("")}, {-0.3, std::nan("")}};
  arm.write_valves(duties);
  const PneumaticArmChain::State state = arm.state();  // by value: a reference into the temporary would dangle
  const BellowsDuties& applied = state.duties[0];
  EXPECT_EQ(applied.inlet[0], 1.0);
  EXPECT_EQ(applied.inlet[1], 0.0);  // a non-finite inlet duty closes it
  EXPECT_EQ(applied.outlet[0], 0.0);
  EXPECT_EQ(applied.outlet[1], 1.0);  // a non-finite outlet duty opens it
  std::vector<BellowsDuties> three(3);
  EXPECT_THROW(arm.write_valves(three), InputError);
  arm.vent();
  for (int i = 0; i < 2; ++i) {
    EXPECT_EQ(arm.state().duties[static_cast<std::size_t>(i)].inlet, (std::array<double, 2>{0.0, 0.0}));
    EXPECT_EQ(arm.state().duties[static_cast<std::size_t>(i)].outlet, (std::array<double, 2>{1.0, 1.0}));
  }
  PneumaticArmChain::State wrong = arm.state();
  wrong.angle_rad.resize(3);
  EXPECT_THROW(arm.set_state(wrong), InputError);
}

TEST(PneumaticArmChain, RefusesParametersItCannotSimulateWithOneLine) {
  auto message = [](const PneumaticChainParameters& p) -> std::string {
    try {
      PneumaticArmChain arm(p, 1);
    } catch (const InputError& e) {
      return e.what();
    }
    return "accepted";
  };
  PneumaticChainParameters p = pneumatic_chain_preset("arm2");
  p.bellows[1].volume_l = 0.0;
  EXPECT_EQ(message(p), "arm joint 2: volume_l must be > 0 = 0.000000");
  p = pneumatic_chain_preset("arm2");
  p.bellows[0].volume_gain_per_rad = 0.6;  // empties a chamber before 1.5 x 95 deg
  EXPECT_EQ(message(p), "arm joint 1: volume_gain_per_rad empties a chamber within 1.5 x the stops = 0.600000");
  p = pneumatic_chain_preset("arm2");
  p.bellows[0].valve_critical_ratio = 1.0;
  EXPECT_EQ(message(p), "arm joint 1: valve_critical_ratio must be in [0, 1) = 1.000000");
  p = pneumatic_chain_preset("arm2");
  p.supply_bar = -1.0;
  EXPECT_NE(message(p).find("supply_bar"), std::string::npos);
  p = pneumatic_chain_preset("arm2");
  p.chain.links[1].stiffness_Nm_per_rad = 0.0;
  EXPECT_EQ(message(p), "arm joint 2: stiffness_Nm_per_rad must be > 0 = 0.000000");
  EXPECT_EQ(message(pneumatic_chain_preset("arm3")), "accepted");
}

TEST(PneumaticArmChain, ReadingWritingAndAdvancingAllocateNothing) {
  for (const char* preset : {"arm2", "arm3"}) {
    PneumaticArmChain arm(pneumatic_chain_preset(preset), 1);
    std::vector<BellowsDuties> duties(static_cast<std::size_t>(arm.joints()));
    EXPECT_EQ(testing_allocations::probe_allocations(), 1);  // the instrument works
    long allocations = 0;
    {
      testing_allocations::Counter counter;
      for (int tick = 0; tick < 50; ++tick) {
        const PneumaticArmChain::Reading r = arm.read_sensors();
        arm.write_valves(commands(duties, r.time_s));
        arm.advance(kTick_s);
        const PneumaticArmChain::State s = arm.state();
        arm.set_state(s);
      }
      allocations = counter.allocations();
    }
    EXPECT_EQ(allocations, 0) << preset;
  }
}

}  // namespace
}  // namespace bellows
