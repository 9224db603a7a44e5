#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "devices/simulated_arm.hpp"
#include "engine/rt/engine_core.hpp"
#include "engine/operator/learning_session.hpp"
#include "engine/learning/noilc_dense.hpp"
#include "engine/model/valve_flow.hpp"

namespace bellows {
namespace {

constexpr double kDeg = std::numbers::pi / 180.0;

ValveCommand inlet_a(double duty) {
  ValveCommand c;
  c.joint[0].inlet_duty = {duty, 0.0};
  return c;
}

double predicted_inlet_rate_Pa_per_s(const PlantParameters& p, double chamber_Pa, double volume_m3) {
  const double flow =
      p.valves_per_port * iso6358_mass_flow_kg_per_s(p.supply_bar * 1e5, chamber_Pa, p.valve_conductance_m3_per_sPa,
                                                     p.valve_critical_ratio, p.gas.reference_density_kg_per_m3);
  return flow * p.gas.gas_constant_J_per_kgK * p.gas.temperature_K / volume_m3;
}

TEST(SimulatedArm, OpenInletRaisesPressureAtTheRateTheFlowModelPredicts) {
  for (double start_bar : {1.01325, 1.2, 1.35}) {  // choked and subsonic flow
    PlantParameters plant;
    SimulatedArm arm(plant, 1);
    SimulatedArm::State s = arm.state();
    s.chamber_Pa = {start_bar * 1e5, start_bar * 1e5};  // balanced: the arm stays at rest at first
    arm.set_state(s);
    const double expected = predicted_inlet_rate_Pa_per_s(plant, start_bar * 1e5, arm.chamber_volume_m3(0));
    arm.write_valves(inlet_a(1.0));
    const double dt = 2e-4;
    arm.advance(dt);
    const double measured = (arm.state().chamber_Pa[0] - start_bar * 1e5) / dt;
    EXPECT_NEAR(measured / expected, 1.0, 0.01) << "start " << start_bar << " bar";
    EXPECT_NEAR(arm.state().chamber_Pa[1], start_bar * 1e5, 1.0);  // B untouched
  }
}

TEST(SimulatedArm, SwitchingValvesOpenForTheDutyCycleOfEachPeriod) {
  PlantParameters plant;
  plant.volume_gain_per_rad = 0.0;  // isolate the valve timing from the arm's motion
  auto rise_over_one_period = [&](double duty) {
    SimulatedArm arm(plant, 1);
    arm.write_valves(inlet_a(duty));
    arm.advance(plant.pwm_period_s);
    return arm.state().chamber_Pa[0] - plant.gas.ambient_bar * 1e5;
  };
  const double full = rise_over_one_period(1.0);
  EXPECT_GT(full, 0.0);
  EXPECT_NEAR(rise_over_one_period(0.5) / full, 0.5, 0.01);
  EXPECT_NEAR(rise_over_one_period(0.13) / full, 0.13, 0.005);  // not quantized to the 0.1 ms step
  EXPECT_EQ(rise_over_one_period(0.0), 0.0);
  // Within a period the valve is open first, then closed: no rise after duty * period.
  SimulatedArm arm(plant, 1);
  arm.write_valves(inlet_a(0.4));
  arm.advance(0.4 * plant.pwm_period_s);
  const double at_edge = arm.state().chamber_Pa[0];
  arm.advance(0.6 * plant.pwm_period_s - 1e-9);
  EXPECT_NEAR(arm.state().chamber_Pa[0], at_edge, 1e-6);
}

TEST(SimulatedArm, ClosedValvesConserveAirMassWhileTheArmMoves) {
  PlantParameters plant;
  SimulatedArm arm(plant, 1);
  SimulatedArm::State s = arm.state();
  s.chamber_Pa = {1.3e5, 1.01325e5};
  arm.set_state(s);
  arm.write_valves(ValveCommand{});  // everything closed
  const double mass_before = arm.air_mass_kg();
  double largest_angle = 0.0;
  for (int i = 0; i < 400; ++i) {
    arm.advance(plant.pwm_period_s);
    largest_angle = std::max(largest_angle, std::abs(arm.state().angle_rad));
  }
  EXPECT_GT(largest_angle, 20.0 * kDeg);  // it really moved
  EXPECT_NEAR(arm.air_mass_kg() / mass_before, 1.0, 1e-9);
  // ...and the gas law changed the pressures as the volumes changed.
  EXPECT_LT(arm.state().chamber_Pa[0], 1.3e5 - 1000.0);
  EXPECT_GT(arm.state().chamber_Pa[1], 1.01325e5 + 1000.0);
}

TEST(SimulatedArm, OutletVentsTowardAmbientAndNoFurther) {
  PlantParameters plant;
  SimulatedArm arm(plant, 1);
  SimulatedArm::State s = arm.state();
  s.chamber_Pa = {1.3e5, 1.3e5};
  arm.set_state(s);
  for (int i = 0; i < 400; ++i) {
    arm.vent();
    arm.advance(plant.pwm_period_s);
  }
  EXPECT_NEAR(arm.state().chamber_Pa[0], plant.gas.ambient_bar * 1e5, 50.0);
  EXPECT_GE(arm.state().chamber_Pa[0], plant.gas.ambient_bar * 1e5 - 1.0);
}

// Runs the paper's first trial (feedback only) and returns the largest amount by which chamber A's
// measured pressure exceeds its set point while A deflates in the fast moves.
double largest_bounce_back_bar(const PlantParameters& plant) {
  ControllerParameters controller;
  TimingParameters timing;
  SimulatedArm arm(plant, 3);
  EngineCore core(arm, controller, timing, SafetyParameters{});
  SimulatedClock clock(core, arm);
  const Trajectory paper = library_trajectory("paper", timing.sample_s());
  NormOptimalDense law(discretize_arm_model(ModelParameters{}, timing.sample_s()), IlcParameters{},
                       paper.learning_samples());
  LearningSession session(clock, law, paper, timing, controller);
  session.run_trial();
  const TrialRecord& record = session.last_record();
  const TrialTicks& t = record.joint_ticks(0);
  double largest = 0.0;
  for (Eigen::Index i = 0; i < record.tick_time_s.size(); ++i) {
    const bool moving_toward_b = record.tick_time_s(i) > 1.6 && record.tick_time_s(i) < 1.9;  // the +30 -> -30 move
    if (moving_toward_b) largest = std::max(largest, t.pressure_a_bar(i) - t.setpoint_a_bar(i));
  }
  return largest;
}

TEST(SimulatedArm, FastMoveMakesTheDeflatingBellowsPushBack) {
  PlantParameters plant;
  const double with_gas_law = largest_bounce_back_bar(plant);
  plant.volume_gain_per_rad = 0.0;  // no volume change: no compression of the shrinking bellows
  const double without = largest_bounce_back_bar(plant);
  EXPECT_GT(with_gas_law, 0.01);  // more than 10 mbar above its set point
  EXPECT_GT(with_gas_law, 2.0 * without);
}

TEST(SimulatedArm, EncoderIsQuantizedAndPressureSensorsAreNoisy) {
  PlantParameters plant;
  SimulatedArm arm(plant, 5);
  SimulatedArm::State s = arm.state();
  s.angle_rad = 12.3456 * kDeg;
  s.creep_rad = plant.creep_gain * s.angle_rad;
  arm.set_state(s);
  const SensorReading r = arm.read_sensors();
  EXPECT_NEAR(r.joint[0].angle_rad / kDeg, 12.3, 1e-9);
  double sum = 0.0, sum_sq = 0.0;
  const int n = 4000;
  for (int i = 0; i < n; ++i) {
    const double noise = arm.read_sensors().joint[0].chamber_bar[0] - plant.gas.ambient_bar;
    sum += noise;
    sum_sq += noise * noise;
  }
  EXPECT_NEAR(sum / n, 0.0, 4.0 * plant.pressure_noise_bar / std::sqrt(n));
  EXPECT_NEAR(std::sqrt(sum_sq / n), plant.pressure_noise_bar, 0.05 * plant.pressure_noise_bar);
}

TEST(SimulatedArm, DeterministicForAGivenSeedAndResumableFromItsState) {
  PlantParameters plant;
  auto run = [&](SimulatedArm& arm, int periods) {
    double signature = 0.0;
    for (int i = 0; i < periods; ++i) {
      const SensorReading r = arm.read_sensors();
      signature += r.joint[0].chamber_bar[0] + 3.0 * r.joint[0].chamber_bar[1] + r.joint[0].angle_rad;
      arm.write_valves(inlet_a(0.3 + 0.2 * std::sin(i * 0.1)));
      arm.advance(plant.pwm_period_s);
    }
    return signature;
  };
  SimulatedArm a(plant, 7), b(plant, 7), c(plant, 8);
  EXPECT_EQ(run(a, 100), run(b, 100));
  SimulatedArm fresh(plant, 7);
  EXPECT_NE(run(fresh, 100), run(c, 100));
  // Copying the state mid-run continues bit for bit.
  SimulatedArm resumed(plant, 99);
  resumed.set_state(a.state());
  EXPECT_EQ(run(a, 50), run(resumed, 50));
}

TEST(SimulatedArm, HardStopsHoldTheArm) {
  PlantParameters plant;
  SimulatedArm arm(plant, 1);
  SimulatedArm::State s = arm.state();
  s.chamber_Pa = {2.9e5, 1.01325e5};  // far more than the joint can take: 15 rad of static deflection
  arm.set_state(s);
  arm.write_valves(ValveCommand{});
  double largest = 0.0;
  for (int i = 0; i < 400; ++i) {
    arm.advance(plant.pwm_period_s);
    largest = std::max(largest, arm.state().angle_rad);
  }
  EXPECT_GT(largest, plant.hard_stop_deg * kDeg);
  EXPECT_LT(largest, (plant.hard_stop_deg + 15.0) * kDeg);
  EXPECT_TRUE(std::isfinite(arm.state().chamber_Pa[0]));
}

}  // namespace
}  // namespace bellows
