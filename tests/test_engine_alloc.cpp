// Proves the loop allocates nothing once running: global operator new is counted while ticks run
// (holding, a whole trial with telemetry taps, a fault and its black box, a reset), with one joint
// and with the three joints of the simulated arm3 chain.
#include <gtest/gtest.h>

#include "devices/simulated_arm_chain.hpp"
#include "engine/model/pneumatic_arm_chain_parameters.hpp"
#include "tests/allocation_counter.hpp"
#include "tests/engine_fixture.hpp"
#include "tests/gappy_device.hpp"

namespace bellows {
namespace {

using CountAllocations = testing_allocations::Counter;

TEST(EngineAllocations, CounterSeesAnAllocation) {  // the instrument works
  EXPECT_EQ(testing_allocations::probe_allocations(), 1);
}

TEST(EngineAllocations, TicksAllocateNothing) {
  testing::EngineFixture f;
  TelemetryRing& tap = f.core.add_telemetry_tap(8192);
  const Trajectory paper = library_trajectory("paper", 0.02);
  Eigen::VectorXd correction = Eigen::VectorXd::Constant(paper.learning_samples(), 0.01);
  TrialRecord record;
  record.prepare(paper.learning_samples(), f.config.timing.ticks_per_sample);  // sized outside the loop
  EXPECT_TRUE(f.core.send(EngineCommand::select_trajectory(paper)));
  f.send(CommandKind::kArm);
  f.clock.step(10);  // warm up outside the count

  const EngineCommand start = EngineCommand::start_trial(paper, correction, record, 100, 1);
  long allocations = 0;
  {
    CountAllocations counter;
    EXPECT_TRUE(f.core.send(start));
    f.clock.step(100 + 4 * 400 + 10);  // settle, the whole trial, back to holding
    f.send(CommandKind::kEmergencyStop);
    f.clock.step(10);
    f.send(CommandKind::kReset);
    f.send(CommandKind::kArm);
    f.clock.step(10);
    allocations = counter.allocations();
  }
  EXPECT_TRUE(record.complete);
  EXPECT_GT(tap.read_available(), 1000u);
  EXPECT_EQ(allocations, 0);
}

TEST(EngineAllocations, RidingThroughMissingReadingsAndADevicesFaultAllocateNothing) {
  const Configuration config;
  SimulatedArm arm(config.plant, 1);
  testing::GappyDevice device(arm);
  EngineCore core(device, config.controller, config.timing, config.safety);
  SimulatedClock clock(core, device);
  const Trajectory paper = library_trajectory("paper", 0.02);
  Eigen::VectorXd correction = Eigen::VectorXd::Constant(paper.learning_samples(), 0.01);
  TrialRecord record;
  record.prepare(paper.learning_samples(), config.timing.ticks_per_sample);
  EXPECT_TRUE(core.send(EngineCommand::select_trajectory(paper)));
  EXPECT_TRUE(core.send(EngineCommand::of(CommandKind::kArm)));
  clock.step(10);
  device.lose_repeatedly(200, config.safety.stale_ticks - 1, 3, 100);  // held ticks in the trial
  DeviceFault trip;
  trip.set(FaultCode::kRigLimit, 0, "the rig stopped joint 1 at %.1f deg", -100.0);
  const EngineCommand start = EngineCommand::start_trial(paper, correction, record, 10, 1);
  long allocations = 0;
  {
    CountAllocations counter;
    EXPECT_TRUE(core.send(start));
    clock.step(10 + 4 * 400 + 10);
    device.report(trip);  // the device's own fault, latched with its words
    clock.step(5);
    device.lose_readings(device.reads(), 100);  // and a loss beyond the stale limit, named by the device
    EXPECT_TRUE(core.send(EngineCommand::of(CommandKind::kReset)));
    EXPECT_TRUE(core.send(EngineCommand::of(CommandKind::kArm)));
    clock.step(20);
    allocations = counter.allocations();
  }
  EXPECT_TRUE(record.complete);
  EXPECT_GT(record.held_samples, 0);
  EXPECT_EQ(core.fault(), FaultCode::kSensorStale);
  EXPECT_EQ(allocations, 0);
}

// A late loop on a rig with its own time: the missed periods held (issue 22), and at the limit the
// fault with its sentence; neither allocates.
TEST(EngineAllocations, ALateLoopRiddenThroughAndFaultingAllocatesNothing) {
  const Configuration config;
  SimulatedArm arm(config.plant, 1);
  testing::GappyDevice device(arm, true);
  EngineCore core(device, config.controller, config.timing, config.safety);
  const Trajectory paper = library_trajectory("paper", 0.02);
  Eigen::VectorXd correction = Eigen::VectorXd::Constant(paper.learning_samples(), 0.01);
  TrialRecord record;
  record.prepare(paper.learning_samples(), config.timing.ticks_per_sample);
  const double tick_s = config.timing.tick_s;
  long long ticks = 0;
  const auto tick = [&](int missed) {  // the rig's time goes on through the missed periods
    device.advance(missed * tick_s);
    ticks += missed;
    core.tick(static_cast<double>(ticks) * tick_s, static_cast<double>(ticks) * tick_s, missed);
    device.advance(tick_s);
    ++ticks;
  };
  EXPECT_TRUE(core.send(EngineCommand::select_trajectory(paper)));
  EXPECT_TRUE(core.send(EngineCommand::of(CommandKind::kArm)));
  for (int i = 0; i < 10; ++i) tick(0);
  const EngineCommand start = EngineCommand::start_trial(paper, correction, record, 10, 1);
  long allocations = 0;
  {
    CountAllocations counter;
    EXPECT_TRUE(core.send(start));
    for (int i = 0; i < 400; ++i) tick(i % 50 == 49 ? config.safety.stale_ticks - 1 : 0);  // ridden through
    tick(config.safety.stale_ticks);  // the limit: vents and faults with its sentence
    allocations = counter.allocations();
  }
  EXPECT_GT(core.held_ticks(), 0u);
  EXPECT_EQ(core.fault(), FaultCode::kMissedDeadlines);
  EXPECT_EQ(allocations, 0);
}

TEST(EngineAllocations, TicksOfThreeJointsAllocateNothing) {
  const Configuration config;
  SimulatedArmChain arm(pneumatic_chain_of(config.plant, ArmParameters{"arm3"}), 1);
  EngineCore core(arm, config.controller, config.timing, config.safety);
  SimulatedClock clock(core, arm);
  TelemetryRing& tap = core.add_telemetry_tap(8192);
  const Trajectory paper3 = library_trajectory("paper3", config.timing.sample_s());
  const Eigen::MatrixXd correction = Eigen::MatrixXd::Constant(paper3.learning_samples(), 3, 0.01);
  TrialRecord record;
  record.prepare(paper3.learning_samples(), config.timing.ticks_per_sample, 3);  // sized outside the loop
  EXPECT_TRUE(core.send(EngineCommand::select_trajectory(paper3)));
  EXPECT_TRUE(core.send(EngineCommand::of(CommandKind::kArm)));
  clock.step(10);  // warm up outside the count
  ASSERT_EQ(core.state(), EngineState::kArmed);

  const EngineCommand start = EngineCommand::start_trial(paper3, correction, record, 100, 1);
  long allocations = 0;
  {
    CountAllocations counter;
    EXPECT_TRUE(core.send(start));
    clock.step(100 + 4 * paper3.learning_samples() + 10);  // settle, the whole trial, back to holding
    core.request_emergency_stop();
    clock.step(10);
    EXPECT_TRUE(core.send(EngineCommand::of(CommandKind::kReset)));
    EXPECT_TRUE(core.send(EngineCommand::of(CommandKind::kArm)));
    clock.step(10);
    allocations = counter.allocations();
  }
  EXPECT_TRUE(record.complete);
  EXPECT_EQ(record.joint_count(), 3);
  EXPECT_EQ(core.state(), EngineState::kArmed);
  EXPECT_GT(tap.read_available(), 1000u);
  EXPECT_EQ(allocations, 0);
}

}  // namespace
}  // namespace bellows
