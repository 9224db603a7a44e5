// The engine driving arm2 over LCM (issue 14): EngineCore on the real-time loop with an LcmDevice of
// two joints, io-sim's RigServer serving the J-joint simulated arm (SimulatedArmChain, arm2), both
// ends on memq:// in this process. A paper2 trial runs and every joint tracks as it does with the
// arm in process (tests/test_multi_joint_engine prints ~9.6 and ~15.0 deg at iteration 0).
#include <gtest/gtest.h>

#include <iostream>

#include "devices/lcm_channels.hpp"
#include "devices/lcm_device.hpp"
#include "devices/lcm_rig_server.hpp"
#include "devices/simulated_arm_chain.hpp"
#include "engine/config/configuration.hpp"
#include "engine/rt/engine_core.hpp"
#include "engine/rt/engine_driver.hpp"
#include "engine/model/pneumatic_arm_chain_parameters.hpp"
#include "engine/rt/realtime_loop.hpp"
#include "engine/trial/trajectory.hpp"
#include "tests/lcm_bench.hpp"
#include "tests/lcm_test_support.hpp"

namespace bellows {
namespace {

/// Iteration 0 (no correction) of `trajectory` on `driver`'s engine, already armed: the record, or a
/// failed test when the engine faults, refuses or does not finish within `timeout_s` of wall time.
TrialRecord feedback_trial(EngineDriver& driver, const Configuration& c, const Trajectory& trajectory,
                           double timeout_s) {
  TrialRecord record;
  record.prepare(trajectory.learning_samples(), c.timing.ticks_per_sample, trajectory.joints());
  const int settle_ticks = static_cast<int>(std::lround(c.timing.settle_s / c.timing.tick_s));
  const Eigen::MatrixXd none = Eigen::MatrixXd::Zero(trajectory.learning_samples(), trajectory.joints());
  EXPECT_TRUE(driver.core().send(EngineCommand::start_trial(trajectory, none, record, settle_ticks, 1)));
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::duration<double>(timeout_s);
  bool completed = false;
  while (!completed && std::chrono::steady_clock::now() < deadline) {
    driver.await();
    EngineEvent event;
    while (driver.core().poll_event(event)) {
      EXPECT_NE(event.kind, EventKind::kCommandRefused) << event.refusal;
      if (event.kind == EventKind::kFault) {
        ADD_FAILURE() << "fault " << fault_name(event.fault);
        return record;
      }
      if (event.kind == EventKind::kTrialComplete && event.trial_id == 1) completed = true;
    }
  }
  EXPECT_TRUE(completed && record.complete) << "the trial did not finish";
  return record;
}

void select_and_arm(EngineDriver& driver, const Trajectory& trajectory) {
  EXPECT_TRUE(driver.core().send(EngineCommand::select_trajectory(trajectory)));
  EXPECT_TRUE(driver.core().send(EngineCommand::of(CommandKind::kArm)));
}

std::vector<double> per_joint_rms_deg(const TrialRecord& record) {
  std::vector<double> rms;
  for (int j = 0; j < record.joint_count(); ++j) rms.push_back(record.joint_rms_error_deg(j));
  return rms;
}

std::vector<double> arm2_in_process(const Configuration& c, const Trajectory& paper2) {
  SimulatedArmChain arm(pneumatic_chain_of(c.plant, ArmParameters{"arm2"}), 1);
  EngineCore core(arm, c.controller, c.timing, c.safety);
  SimulatedClock clock(core, arm);
  select_and_arm(clock, paper2);
  clock.step();
  EXPECT_EQ(core.state(), EngineState::kArmed);
  return per_joint_rms_deg(feedback_trial(clock, c, paper2, 60.0));
}

TEST(LcmJointClosedLoop, TheEngineDrivesArm2OverMemqAndEveryJointTracksAsInProcess) {
  Configuration c;
  // About learning over the bus on the wall clock: a loaded 2-core machine may keep the I/O thread
  // off its core longer than the default 3 ticks (the stale guard has exact-tick tests elsewhere).
  c.safety.stale_ticks = 40;
  // Likewise the engine's own wake-ups and the rig's command timeout (their guards have tests of
  // their own): a build beside the suite stalls threads for longer than 5 ticks or 50 ms.
  c.safety.missed_deadline_streak = 1000;
  c.lcm.rig_timeout_s = 1.0;
  const Trajectory paper2 = library_trajectory("paper2", c.timing.sample_s());
  const PneumaticChainParameters arm2 = pneumatic_chain_of(c.plant, ArmParameters{"arm2"});
  SimulatedArmChain arm(arm2, 1);
  std::vector<std::string> rig_log;
  RigServer rig(arm, arm.joints(), arm2.chain.integration_step_s, testing::RigBench::parameters(c, LcmKey{}, rig_log),
                77);
  LcmDevice device(LcmDevice::random_session_id(), LcmKey{}, c.lcm.rig_timeout_s, 2);
  device.set_tick_phase_lock(TickPhaseLock::Parameters::of(c.timing, c.lcm));  // as `--device lcm` runs
  testing::BusRecorder commands(kIoCommandChannel);
  LcmIoThread io("memq://", {&device, &rig, &commands});  // memq: one handle, so one thread for both ends
  io.start(RealtimeMode::kTry, 70);
  EngineCore core(device, c.controller, c.timing, c.safety);
  RealtimeLoop loop(core, device, 1.0);
  loop.start(RealtimeMode::kTry);
  ASSERT_TRUE(testing::eventually([&] { return device.connected(); }, 10.0)) << "the rig never answered";
  select_and_arm(loop, paper2);
  ASSERT_TRUE(testing::eventually([&] { return core.state() == EngineState::kArmed; }, 5.0));
  const TrialRecord record = feedback_trial(loop, c, paper2, 60.0);
  loop.stop();
  io.stop();

  ASSERT_EQ(record.joint_count(), 2);
  const std::vector<double> over_lcm = per_joint_rms_deg(record);
  const std::vector<double> in_process = arm2_in_process(c, paper2);
  for (int j = 0; j < 2; ++j) {
    std::cout << "arm2/paper2 iteration 0, joint " << j + 1 << ": RMS " << over_lcm[static_cast<std::size_t>(j)]
              << " deg over LCM, " << in_process[static_cast<std::size_t>(j)] << " deg in process\n";
    EXPECT_NEAR(over_lcm[static_cast<std::size_t>(j)], in_process[static_cast<std::size_t>(j)],
                0.15 * in_process[static_cast<std::size_t>(j)])
        << "joint " << j + 1;
  }
  const LcmDeviceStats d = device.stats();
  EXPECT_EQ(d.states.other_joints, 0u);
  EXPECT_EQ(d.states.invalid, 0u);
  EXPECT_EQ(rig.stats().commands.ignored(), 0u);
  EXPECT_EQ(rig.stats().sessions_served, 1u);
  // Every command on the bus was a two-joint message.
  for (const testing::Recorded& r : commands.messages()) {
    io_joints_command_t command{};
    ASSERT_EQ(decode_io_command(r.bytes.data(), r.bytes.size(), command), DecodeStatus::kOk);
    ASSERT_EQ(command.joint_count, 2);
  }
  EXPECT_GT(commands.size(), 1000u);
}

/// Iteration 0 of paper2 on arm2 in lockstep over memq: RigServer stepped, LcmDevice waiting for each
/// answer, the engine on the simulated clock of this thread. The record's per-joint RMS, and the rig's.
struct LockstepTrial {
  std::vector<double> rms_deg;
  RigServerStats rig;
  LcmDeviceStats device;
};
LockstepTrial arm2_in_lockstep(const Configuration& c, const Trajectory& paper2) {
  const PneumaticChainParameters arm2 = pneumatic_chain_of(c.plant, ArmParameters{"arm2"});
  SimulatedArmChain arm(arm2, 1);
  std::vector<std::string> rig_log;
  RigServerParameters params = testing::RigBench::parameters(c, LcmKey{}, rig_log);
  params.stepped = true;
  params.command_timeout_s = c.lcm.lockstep_timeout_s;
  RigServer rig(arm, arm.joints(), arm2.chain.integration_step_s, params, 77);
  LcmDevice device(LcmDevice::random_session_id(), LcmKey{}, c.lcm.rig_timeout_s, 2);
  device.set_lockstep(c.lcm.lockstep_timeout_s);
  LcmIoThread io("memq://", {&device, &rig});
  io.start(RealtimeMode::kOff, 0);
  EngineCore core(device, c.controller, c.timing, c.safety);
  SimulatedClock clock(core, device);
  for (int i = 0; i < 2000 && !device.connected(); ++i) clock.step();  // the ticks send the commands that bind
  EXPECT_TRUE(device.connected()) << "the rig never answered";
  select_and_arm(clock, paper2);
  clock.step();
  EXPECT_EQ(core.state(), EngineState::kArmed);
  const TrialRecord record = feedback_trial(clock, c, paper2, 120.0);
  io.stop();
  return {per_joint_rms_deg(record), rig.stats(), device.stats()};
}

// The same trial twice gives the same numbers up to the binding: the ticks sent before the engine
// hears that the rig serves it are not waited for, so the rig's arm may take a vented step or two
// more before the trial (its noise drawn at other times): 0.1 % under ThreadSanitizer, bit for bit
// otherwise as measured (docs/lcm-protocol.md, "Lockstep"). The wall clock's 15 % is not in it.
TEST(LcmJointClosedLoop, InLockstepTheSameTrialGivesTheSameNumbersTwiceAndTracksAsInProcess) {
  // The default safety limits: in lockstep a stall of either thread delays the trial, nothing else.
  const Configuration c;
  const Trajectory paper2 = library_trajectory("paper2", c.timing.sample_s());
  const LockstepTrial first = arm2_in_lockstep(c, paper2), second = arm2_in_lockstep(c, paper2);
  const std::vector<double> in_process = arm2_in_process(c, paper2);
  ASSERT_EQ(first.rms_deg.size(), 2u);
  ASSERT_EQ(second.rms_deg.size(), 2u);
  for (std::size_t j = 0; j < 2; ++j) EXPECT_NEAR(first.rms_deg[j], second.rms_deg[j], 0.005 * first.rms_deg[j]);
  for (std::size_t j = 0; j < 2; ++j) {
    std::cout << "lockstep arm2/paper2 iteration 0, joint " << j + 1 << ": RMS " << first.rms_deg[j]
              << " deg over LCM, " << in_process[j] << " deg in process\n";
    // Not bit-identical to the arm in process: the rig reads its sensors (drawing their noise) at
    // every integration step, the engine in process once per tick.
    EXPECT_NEAR(first.rms_deg[j], in_process[j], 0.01 * in_process[j]) << "joint " << j + 1;
  }
  const std::uint64_t trial_ticks = static_cast<std::uint64_t>(paper2.learning_samples() * c.timing.ticks_per_sample);
  EXPECT_GE(first.rig.commands.accepted, trial_ticks);
  EXPECT_EQ(first.rig.commands.ignored(), 0u);
  EXPECT_EQ(first.rig.timeouts, 0u);
  EXPECT_EQ(first.device.states.ignored(), 0u);
}

}  // namespace
}  // namespace bellows
