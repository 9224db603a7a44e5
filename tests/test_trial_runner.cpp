// The trial runner (engine/operator/trial_runner): the one protocol by which headless runs, the console and
// identification run a trial. Polled tick by tick on the simulated clock with the simulated arm: a
// trial that completes, one the engine faults mid-way, refused starts (unarmed, arm refused), a full
// command queue, cancel() and the stop flag; and the same record whether the runner reads the
// engine's events itself (poll) or is handed them (observe), step by step or run to completion.
#include <atomic>
#include <cmath>
#include <stdexcept>
#include <vector>

#include <gtest/gtest.h>

#include "devices/simulated_arm.hpp"
#include "engine/config/configuration.hpp"
#include "engine/rt/engine_core.hpp"
#include "engine/operator/trial_runner.hpp"
#include "engine/base/units.hpp"
#include "test_support.hpp"

namespace bellows {
namespace {

// A simulated arm with its engine on the simulated clock, and a short trajectory: a 20 deg move.
struct RunnerRig {
  explicit RunnerRig(Configuration c = {})
      : config(c),
        arm(config.plant, 7),
        core(arm, config.controller, config.timing, config.safety),
        clock(core, arm),
        trajectory(trajectory_from_moves("move", 0.0, {{0.2, 0.0, 20.0, 0.4, 12000.0}}, 1.0, config.timing.sample_s())),
        correction(Eigen::MatrixXd::Zero(trajectory.learning_samples(), 1)) {}

  Configuration config;
  SimulatedArm arm;
  EngineCore core;
  SimulatedClock clock;
  Trajectory trajectory;
  Eigen::MatrixXd correction;
  TrialRecord record;
};

// Polls once per tick until the trial is finished (at most `max_ticks`), noting each phase entered.
std::vector<TrialPhase> poll_tick_by_tick(TrialRunner& runner, SimulatedClock& clock, long max_ticks = 100000) {
  std::vector<TrialPhase> phases{runner.status().phase};
  for (long tick = 0; tick < max_ticks && !runner.poll().finished(); ++tick) {
    if (runner.status().phase != phases.back()) phases.push_back(runner.status().phase);
    clock.step(1);
  }
  if (runner.status().phase != phases.back()) phases.push_back(runner.status().phase);
  return phases;
}

TEST(TrialRunner, PolledTickByTickItArmsSettlesRunsAndHandsBackACompleteRecord) {
  RunnerRig rig;
  TrialRunner runner(rig.core, rig.config.timing);
  EXPECT_EQ(runner.status().phase, TrialPhase::kIdle);
  EXPECT_EQ(runner.start(rig.trajectory, rig.correction, rig.record, TrialRunner::Arming::kIfNeeded).phase,
            TrialPhase::kArming);
  EXPECT_EQ(rig.record.learning_samples, rig.trajectory.learning_samples());  // prepared by start()

  int last_sample = -1;
  bool samples_in_order = true;
  std::vector<TrialPhase> phases{runner.status().phase};
  while (!runner.poll().finished() && rig.clock.ticks() < 100000) {
    const TrialStatus& s = runner.status();
    if (s.phase != phases.back()) phases.push_back(s.phase);
    if (s.phase == TrialPhase::kRunning) {
      samples_in_order = samples_in_order && s.sample >= last_sample;
      last_sample = s.sample;
    }
    rig.clock.step(1);
  }
  phases.push_back(runner.status().phase);
  const std::vector<TrialPhase> expected{TrialPhase::kArming, TrialPhase::kWaiting, TrialPhase::kSettling,
                                         TrialPhase::kRunning, TrialPhase::kDone};
  EXPECT_EQ(phases, expected);
  EXPECT_TRUE(samples_in_order);
  EXPECT_GE(last_sample, rig.trajectory.learning_samples() - 1);
  EXPECT_TRUE(rig.record.complete);
  EXPECT_EQ(runner.status().trial_id, 1u);
  EXPECT_EQ(rig.core.state(), EngineState::kArmed);
  // Arming, the settling and the trajectory's samples: the ticks the trial took, no more.
  const long settle_ticks = std::lround(rig.config.timing.settle_s / rig.config.timing.tick_s);
  const long trial_ticks = static_cast<long>(rig.trajectory.learning_samples()) * rig.config.timing.ticks_per_sample;
  EXPECT_GE(rig.clock.ticks(), settle_ticks + trial_ticks);
  EXPECT_LE(rig.clock.ticks(), settle_ticks + trial_ticks + 4);

  // Armed now: the next trial is sent at once, with the next id, and is run to completion.
  EXPECT_EQ(runner.start(rig.trajectory, rig.correction, rig.record, TrialRunner::Arming::kIfNeeded).phase,
            TrialPhase::kWaiting);
  EXPECT_EQ(runner.run_to_completion(rig.clock).phase, TrialPhase::kDone);
  EXPECT_EQ(runner.status().trial_id, 2u);
  EXPECT_TRUE(rig.record.complete);
}

// [timing] settle_max_s and settle_tolerance_deg reach the engine: the hold at the start goes on
// while the joint is off its first set point, up to settle_max_s; a joint at its start after settle_s
// starts then, as before.
TEST(TrialRunner, TheHoldGoesOnWhileTheJointIsOffItsStartUpToSettleMaxS) {
  // The move of RunnerRig from `start_deg`: the arm at rest reads 0 exactly, and no quantized
  // reading (0.1 deg steps) is ever 5.05 deg.
  const auto ticks_of_a_trial = [](double start_deg, double settle_max_s, double tolerance_deg) {
    Configuration c;
    c.timing.settle_max_s = settle_max_s;
    c.timing.settle_tolerance_deg = tolerance_deg;
    RunnerRig rig(c);
    rig.trajectory =
        trajectory_from_moves("move", start_deg, {{0.2, start_deg, 20.0, 0.4, 12000.0}}, 1.0, c.timing.sample_s());
    TrialRunner runner(rig.core, rig.config.timing);
    runner.start(rig.trajectory, rig.correction, rig.record, TrialRunner::Arming::kIfNeeded);
    EXPECT_EQ(runner.run_to_completion(rig.clock).phase, TrialPhase::kDone);
    return rig.clock.ticks();
  };
  const Configuration defaults;
  const long settle_ticks = std::lround(defaults.timing.settle_s / defaults.timing.tick_s);
  const long longest_ticks = std::lround(3.0 / defaults.timing.tick_s);
  const long plain = ticks_of_a_trial(0.0, 0.0, 0.5);
  EXPECT_EQ(ticks_of_a_trial(0.0, 3.0, 1e-9), plain) << "at its start after settle_s: no longer";
  EXPECT_EQ(ticks_of_a_trial(5.05, 0.0, 1e-9), plain) << "no settle_max_s: settle_s, wherever the joint is";
  EXPECT_EQ(ticks_of_a_trial(5.05, 3.0, 1e-9), plain - settle_ticks + longest_ticks) << "never at 5.05 deg";
}

TEST(TrialRunner, StepByStepAndRunToCompletionAndFedEventsGiveTheSameRecord) {
  RunnerRig polled, run, fed;
  TrialRunner a(polled.core, polled.config.timing), b(run.core, run.config.timing), c(fed.core, fed.config.timing);
  a.start(polled.trajectory, polled.correction, polled.record, TrialRunner::Arming::kIfNeeded);
  poll_tick_by_tick(a, polled.clock);
  b.start(run.trajectory, run.correction, run.record, TrialRunner::Arming::kIfNeeded);
  b.run_to_completion(run.clock);
  // A caller that reads the engine's events and snapshot itself (the console) hands them over.
  c.start(fed.trajectory, fed.correction, fed.record, TrialRunner::Arming::kIfNeeded);
  bool ran = false;
  for (long tick = 0; tick < 100000 && !c.status().finished(); ++tick) {
    EngineEvent event;
    while (fed.core.poll_event(event)) c.observe(event);
    TickRecord latest;
    if (fed.core.read_snapshot(latest) && c.observe(latest)) ran = ran || c.status().phase == TrialPhase::kRunning;
    if (!c.status().finished()) fed.clock.step(1);
  }
  EXPECT_TRUE(ran);
  for (const TrialRunner* r : {&a, &b, &c}) EXPECT_EQ(r->status().phase, TrialPhase::kDone);
  EXPECT_EQ(polled.clock.ticks(), run.clock.ticks());
  EXPECT_EQ(polled.clock.ticks(), fed.clock.ticks());
  EXPECT_EQ(polled.record.joint_samples(0).angle_rad, run.record.joint_samples(0).angle_rad);
  EXPECT_EQ(polled.record.joint_samples(0).angle_rad, fed.record.joint_samples(0).angle_rad);
  EXPECT_EQ(polled.record.joint_samples(0).u_total_bar, fed.record.joint_samples(0).u_total_bar);
}

TEST(TrialRunner, AGuardFiringMidTrialEndsItFaultedWithTheFaultCode) {
  Configuration config;
  config.safety.angle_limit_deg = 10.0;  // the 20 deg move crosses it
  RunnerRig rig(config);
  TrialRunner runner(rig.core, rig.config.timing);
  runner.start(rig.trajectory, rig.correction, rig.record, TrialRunner::Arming::kIfNeeded);
  const std::vector<TrialPhase> phases = poll_tick_by_tick(runner, rig.clock);
  ASSERT_EQ(runner.status().phase, TrialPhase::kFaulted) << to_string(runner.status().phase);
  EXPECT_EQ(phases[phases.size() - 2], TrialPhase::kRunning);  // mid-trial, not before it
  EXPECT_EQ(runner.status().fault, FaultCode::kAngleLimit);
  EXPECT_EQ(runner.status().message, fault_message(FaultCode::kAngleLimit));
  EXPECT_FALSE(rig.record.complete);
  EXPECT_EQ(rig.core.state(), EngineState::kFault);
  EXPECT_TRUE(testing::vented(rig.arm.state().command));
  // Finished: polling again changes nothing.
  EXPECT_EQ(runner.poll().phase, TrialPhase::kFaulted);
}

// The snapshot's latest-value buffer has one reader: a runner that leaves it to another (the
// LearningSession beside a console) follows the trial by events alone and never takes a snapshot.
TEST(TrialRunner, ARunnerLeavingTheSnapshotToOthersNeverReadsIt) {
  RunnerRig rig;
  TrialRunner runner(rig.core, rig.config.timing, TrialRunner::Snapshot::kLeaveToOthers);
  runner.start(rig.trajectory, rig.correction, rig.record, TrialRunner::Arming::kIfNeeded);
  EXPECT_EQ(runner.run_to_completion(rig.clock).phase, TrialPhase::kDone);
  EXPECT_TRUE(rig.record.complete);
  TickRecord tick;
  EXPECT_TRUE(rig.core.read_snapshot(tick)) << "the runner took the snapshot its reader was owed";
  EXPECT_GT(tick.time_s, 0.0);
  EXPECT_EQ(runner.latest_tick().time_s, 0.0);
}

TEST(TrialRunner, AnUnarmedEngineRefusesATrialThatMustNotArm) {
  RunnerRig rig;
  TrialRunner runner(rig.core, rig.config.timing);
  EXPECT_EQ(runner.start(rig.trajectory, rig.correction, rig.record, TrialRunner::Arming::kMustBeArmed).phase,
            TrialPhase::kWaiting);
  poll_tick_by_tick(runner, rig.clock, 10);
  const TrialStatus& s = runner.status();
  ASSERT_EQ(s.phase, TrialPhase::kRefused) << to_string(s.phase);
  EXPECT_EQ(s.command, CommandKind::kStartTrial);
  EXPECT_FALSE(s.message.empty());
  EXPECT_EQ(rig.core.state(), EngineState::kSafe);  // never armed
}

TEST(TrialRunner, AnArmRefusedInFaultIsReportedAsTheArmsRefusal) {
  RunnerRig rig;
  rig.core.request_emergency_stop();
  rig.clock.step(1);
  ASSERT_EQ(rig.core.state(), EngineState::kFault);
  TrialRunner runner(rig.core, rig.config.timing);
  runner.start(rig.trajectory, rig.correction, rig.record, TrialRunner::Arming::kIfNeeded);
  const TrialStatus& s = runner.run_to_completion(rig.clock);
  ASSERT_EQ(s.phase, TrialPhase::kRefused) << to_string(s.phase);
  EXPECT_EQ(s.command, CommandKind::kArm);
  EXPECT_EQ(s.fault, FaultCode::kEmergencyStop);
  EXPECT_FALSE(s.message.empty());
}

TEST(TrialRunner, AFullCommandQueueLeavesTheTrialNotSent) {
  RunnerRig rig;
  for (int i = 0; i < 1000000 && rig.core.send(EngineCommand::of(CommandKind::kHeartbeat)); ++i) {
  }
  TrialRunner runner(rig.core, rig.config.timing);
  const TrialStatus& s = runner.start(rig.trajectory, rig.correction, rig.record, TrialRunner::Arming::kIfNeeded);
  EXPECT_EQ(s.phase, TrialPhase::kNotSent);
  EXPECT_EQ(s.command, CommandKind::kArm);
  EXPECT_NE(s.message.find("queue is full"), std::string::npos) << s.message;
  EXPECT_TRUE(s.finished());
}

TEST(TrialRunner, CancelMidTrialVentsAtTheNextTickAndEndsCancelled) {
  RunnerRig rig;
  TrialRunner runner(rig.core, rig.config.timing);
  runner.start(rig.trajectory, rig.correction, rig.record, TrialRunner::Arming::kIfNeeded);
  while (runner.poll().phase != TrialPhase::kRunning && rig.clock.ticks() < 100000) rig.clock.step(1);
  ASSERT_EQ(runner.status().phase, TrialPhase::kRunning);
  runner.cancel();
  EXPECT_TRUE(runner.cancelling());
  EXPECT_FALSE(runner.poll().finished());  // the engine has not ticked yet
  rig.clock.step(1);
  EXPECT_EQ(runner.poll().phase, TrialPhase::kCancelled);
  EXPECT_EQ(runner.status().fault, FaultCode::kEmergencyStop);
  EXPECT_EQ(rig.core.state(), EngineState::kFault);
  EXPECT_TRUE(testing::vented(rig.arm.state().command));
  EXPECT_FALSE(rig.record.complete);
}

TEST(TrialRunner, ASetStopFlagCancelsARunToCompletion) {
  RunnerRig rig;
  TrialRunner runner(rig.core, rig.config.timing);
  std::atomic<bool> stop{false};
  runner.start(rig.trajectory, rig.correction, rig.record, TrialRunner::Arming::kIfNeeded);
  int polls = 0;
  const TrialStatus& s = runner.run_to_completion(rig.clock, &stop, [&](const TickRecord&) {
    if (++polls == 50) stop = true;  // a signal arrives mid-trial
  });
  EXPECT_EQ(s.phase, TrialPhase::kCancelled);
  EXPECT_EQ(polls, 50);  // the guard is not asked again once cancelling
  EXPECT_EQ(rig.core.state(), EngineState::kFault);
  EXPECT_TRUE(testing::vented(rig.arm.state().command));
}

TEST(TrialRunner, AGuardOfTheCallerSeesEveryPollAndMayCancel) {
  RunnerRig rig;
  TrialRunner runner(rig.core, rig.config.timing);
  runner.start(rig.trajectory, rig.correction, rig.record, TrialRunner::Arming::kIfNeeded);
  double cancelled_at_deg = 0.0;
  const TrialStatus& s = runner.run_to_completion(rig.clock, nullptr, [&](const TickRecord& tick) {
    if (tick.reading.joint[0].angle_rad * kDegPerRad > 5.0) {
      cancelled_at_deg = tick.reading.joint[0].angle_rad * kDegPerRad;
      runner.cancel();
    }
  });
  EXPECT_EQ(s.phase, TrialPhase::kCancelled);
  EXPECT_GT(cancelled_at_deg, 5.0);
  EXPECT_LT(cancelled_at_deg, 6.0);  // looked at every tick: caught as it crossed
}

TEST(TrialRunner, StartingWhileATrialIsInProgressIsALogicError) {
  RunnerRig rig;
  TrialRunner runner(rig.core, rig.config.timing);
  runner.start(rig.trajectory, rig.correction, rig.record, TrialRunner::Arming::kIfNeeded);
  TrialRecord other;
  EXPECT_THROW(runner.start(rig.trajectory, rig.correction, other, TrialRunner::Arming::kIfNeeded), std::logic_error);
  EXPECT_EQ(runner.run_to_completion(rig.clock).phase, TrialPhase::kDone);
}

}  // namespace
}  // namespace bellows
