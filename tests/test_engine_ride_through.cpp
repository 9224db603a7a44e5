// The engine rides through missing readings (issue 22): a tick without a fresh reading holds every
// valve closed and runs no controller, the trial goes on and records the sample as held (error 0,
// nothing learned from it); [safety] stale_ticks of them in a row fault, named by the device. A
// device's own fault (the rig's trip) is latched with the device's words and joint. On a rig whose
// time is its own, periods the loop missed are held the same way and count towards that limit.
#include <cstring>
#include <set>
#include <string>

#include <gtest/gtest.h>

#include "devices/simulated_arm.hpp"
#include "engine/config/configuration.hpp"
#include "engine/rt/engine_core.hpp"
#include "engine/rt/engine_driver.hpp"
#include "tests/gappy_device.hpp"

namespace bellows {
namespace {

struct GappyEngine {
  explicit GappyEngine(const Configuration& c = Configuration{}, bool own_time = false)
      : config(c),
        arm(c.plant, 1),
        device(arm, own_time),
        core(device, c.controller, c.timing, c.safety),
        clock(core, device) {}
  /// One tick of a loop that woke `missed` periods late: the rig's time went on meanwhile.
  void step_late(int missed) {
    const double tick_s = config.timing.tick_s;
    device.advance(missed * tick_s);
    clock.set_ticks(clock.ticks() + missed);
    const double now = clock.now_s();
    core.tick(now, now, missed);
    device.advance(tick_s);
    clock.set_ticks(clock.ticks() + 1);
  }
  std::vector<EngineEvent> drain() {
    std::vector<EngineEvent> events;
    EngineEvent e;
    while (core.poll_event(e)) events.push_back(e);
    return events;
  }
  /// Arms and runs one trial of `trajectory` to its end (or a fault); the record is returned.
  /// With `late_at` >= 0, the loop's wake-up `late_at` ticks into the trial comes `missed` periods late.
  void run_trial(const Trajectory& trajectory, TrialRecord& record, long late_at = -1, int missed = 0) {
    correction = Eigen::VectorXd::Zero(trajectory.learning_samples());
    record.prepare(trajectory.learning_samples(), config.timing.ticks_per_sample);
    EXPECT_TRUE(core.send(EngineCommand::select_trajectory(trajectory)));
    EXPECT_TRUE(core.send(EngineCommand::of(CommandKind::kArm)));
    clock.step(20);
    EXPECT_TRUE(core.send(EngineCommand::start_trial(trajectory, correction, record, 10, 7)));
    const long ticks = 10 + static_cast<long>(trajectory.learning_samples()) * config.timing.ticks_per_sample + 20;
    for (long i = 0; i < ticks && core.state() != EngineState::kFault; ++i) {
      if (i == late_at) {
        step_late(missed);
      } else {
        clock.step();
      }
    }
  }
  /// The engine time of the trial's end (its kTrialComplete event), -1 without one.
  double trial_end_s() {
    for (const EngineEvent& event : drain()) {
      if (event.kind == EventKind::kTrialComplete) return event.time_s;
    }
    return -1.0;
  }
  Configuration config;
  SimulatedArm arm;
  testing::GappyDevice device;
  EngineCore core;
  SimulatedClock clock;
  Eigen::VectorXd correction;
};

TEST(EngineRideThrough, GapsShorterThanTheStaleLimitCostTheirTicksNotTheTrial) {
  const Trajectory paper = library_trajectory("paper", 0.02);
  TrialRecord clean;
  {
    GappyEngine e;
    e.run_trial(paper, clean);
  }
  GappyEngine e;
  const int gap = e.config.safety.stale_ticks - 1;  // the longest gap that rides through
  ASSERT_GE(gap, 1);
  // Gaps of `gap` readings, 5 fresh ones between them, over the middle of the trial: some fall on
  // the ILC's sample ticks (every 4th), whatever the phase.
  e.device.lose_repeatedly(600, gap, 5, 40);
  TrialRecord record;
  e.run_trial(paper, record);
  ASSERT_TRUE(clean.complete);
  ASSERT_TRUE(record.complete) << "faulted: " << fault_name(e.core.fault());
  EXPECT_EQ(e.core.state(), EngineState::kArmed);
  EXPECT_EQ(e.core.held_ticks(), static_cast<std::uint64_t>(gap) * 40);
  ASSERT_GT(record.held_samples, 0);
  int held = 0;
  const int tps = e.config.timing.ticks_per_sample;
  for (int k = 0; k <= paper.learning_samples(); ++k) {
    if (record.held[static_cast<std::size_t>(k)] == 0) continue;
    ++held;
    EXPECT_EQ(record.joint_samples(0).error_rad(k), 0.0) << "held sample " << k << " must not be learned from";
    if (k < paper.learning_samples()) {  // its tick held every valve closed: nothing can inflate
      const int i = k * tps;
      EXPECT_EQ(record.joint_ticks(0).inlet_a(i), 0.0);
      EXPECT_EQ(record.joint_ticks(0).inlet_b(i), 0.0);
      EXPECT_EQ(record.joint_ticks(0).outlet_a(i), 0.0);
      EXPECT_EQ(record.joint_ticks(0).outlet_b(i), 0.0);
    }
  }
  EXPECT_EQ(held, record.held_samples);
  EXPECT_EQ(record.normalized_error().cwiseAbs().maxCoeff() > 0.0, true);
  // Control resumed: the trial tracks about as well as without gaps.
  EXPECT_NEAR(record.rms_error_deg(), clean.rms_error_deg(), 0.15 * clean.rms_error_deg());
  EXPECT_EQ(clean.held_samples, 0);
}

TEST(EngineRideThrough, ALossAsLongAsTheStaleLimitVentsAndFaultsNamedByTheDevice) {
  GappyEngine e;
  const int limit = e.config.safety.stale_ticks;
  e.device.lose_readings(800, 100000);
  TrialRecord record;
  e.run_trial(library_trajectory("paper", 0.02), record);
  ASSERT_EQ(e.core.state(), EngineState::kFault);
  EXPECT_EQ(e.core.fault(), FaultCode::kSensorStale);  // an in-process device: the default explanation
  EXPECT_FALSE(record.complete);
  EXPECT_EQ(e.core.held_ticks(), static_cast<std::uint64_t>(limit - 1));
  bool fault_seen = false;
  for (const EngineEvent& event : e.drain()) {
    if (event.kind != EventKind::kFault) continue;
    fault_seen = true;
    EXPECT_NE(std::strstr(event.detail.data(), "no fresh reading for"), nullptr) << event.detail.data();
  }
  EXPECT_TRUE(fault_seen);
  TickRecord tick;
  e.core.read_snapshot(tick);
  EXPECT_EQ(tick.valves.joint[0].outlet_duty[0], 1.0);  // vented
  EXPECT_EQ(tick.valves.joint[0].outlet_duty[1], 1.0);
}

TEST(EngineRideThrough, ASilenceWhileSafeIsNotCountedAgainstTheTickThatArms) {
  // A rig that was not serving yet (no reading while the engine was safe, its valves vented) and
  // answers in the tick that arms: only ticks with live valves count towards the stale limit.
  GappyEngine e;
  const int limit = e.config.safety.stale_ticks;
  e.device.lose_readings(1, 5 * limit);
  e.clock.step(1 + 5 * limit);
  ASSERT_EQ(e.core.state(), EngineState::kSafe);
  ASSERT_TRUE(e.core.send(EngineCommand::of(CommandKind::kArm)));
  e.clock.step();  // the first fresh reading, in the tick that arms
  EXPECT_EQ(e.core.state(), EngineState::kArmed);
  EXPECT_EQ(e.core.fault(), FaultCode::kNone);
  // From the arm on, the limit acts as ever.
  e.device.lose_readings(e.device.reads(), limit);
  e.clock.step(limit - 1);
  EXPECT_EQ(e.core.state(), EngineState::kArmed);
  e.clock.step();
  EXPECT_EQ(e.core.state(), EngineState::kFault);
  EXPECT_EQ(e.core.fault(), FaultCode::kSensorStale);
}

TEST(EngineRideThrough, ADevicesOwnFaultIsLatchedWithItsWordsAndJoint) {
  GappyEngine e;
  EXPECT_TRUE(e.core.send(EngineCommand::of(CommandKind::kArm)));
  e.clock.step(10);
  DeviceFault trip;
  trip.set(FaultCode::kRigLimit, 0,
           "the rig stopped joint %d at %.0f deg beyond its range %d deg: check the chamber wiring", 1, -100.0, 100);
  e.device.report(trip);
  e.drain();
  e.clock.step();
  ASSERT_EQ(e.core.fault(), FaultCode::kRigLimit);
  EXPECT_STREQ(fault_name(e.core.fault()), "rig-limit");
  bool fault_seen = false;
  for (const EngineEvent& event : e.drain()) {
    if (event.kind != EventKind::kFault) continue;
    fault_seen = true;
    EXPECT_EQ(event.fault_joint, 0);
    EXPECT_STREQ(event.detail.data(),
                 "the rig stopped joint 1 at -100 deg beyond its range 100 deg: check the chamber wiring");
  }
  EXPECT_TRUE(fault_seen);
  // Reset clears the words: the next fault has its own.
  EXPECT_TRUE(e.core.send(EngineCommand::of(CommandKind::kReset)));
  EXPECT_TRUE(e.core.send(EngineCommand::of(CommandKind::kEmergencyStop)));
  e.clock.step();
  for (const EngineEvent& event : e.drain()) {
    if (event.kind == EventKind::kFault) {
      EXPECT_STREQ(event.detail.data(), fault_message(FaultCode::kEmergencyStop));
    }
  }
}

TEST(EngineRideThrough, ADeviceFaultWhileVentedIsTakenButNotLatched) {
  GappyEngine e;
  DeviceFault trip;
  trip.set(FaultCode::kRigTimeout, -1, "the rig vented by itself");
  e.device.report(trip);
  e.clock.step(3);
  EXPECT_EQ(e.core.state(), EngineState::kSafe);
  EXPECT_EQ(e.core.fault(), FaultCode::kNone);
  EXPECT_TRUE(e.core.send(EngineCommand::of(CommandKind::kArm)));
  e.clock.step(10);
  EXPECT_EQ(e.core.state(), EngineState::kArmed);  // the old report does not fire on arming
}

TEST(EngineLateLoop, ARigTimeoutReportedAfterTheLoopStalledPastItsStreakIsTheLoopsFault) {
  // The rig vented itself because this loop stalled (a stopped process, a host that did not run it):
  // after the stall the rig's report and the loop's lateness arrive in one tick, in either order.
  // What happened is the stall; the rig's report is its consequence.
  for (const bool stalled : {true, false}) {
    GappyEngine e(Configuration{}, true);
    EXPECT_TRUE(e.core.send(EngineCommand::of(CommandKind::kArm)));
    e.clock.step(10);
    DeviceFault timeout;
    timeout.set(FaultCode::kRigTimeout, -1, "the rig heard no command for its timeout and vented itself");
    e.device.report(timeout);
    if (stalled) {
      e.step_late(e.config.safety.missed_deadline_streak);
    } else {
      e.clock.step();
    }
    EXPECT_EQ(e.core.state(), EngineState::kFault);
    EXPECT_EQ(e.core.fault(), stalled ? FaultCode::kMissedDeadlines : FaultCode::kRigTimeout)
        << (stalled ? "after a stall" : "on time") << ": " << fault_name(e.core.fault());
  }
}

// Missed deadlines on a rig whose time is its own (docs/architecture.md): the periods the loop
// missed passed on the rig without a command; below the limits they are held like missing readings.
TEST(EngineLateLoop, ALateWakeUpBelowTheLimitRidesThroughAsHeldTicksOnTheRigsClock) {
  const Trajectory paper = library_trajectory("paper", 0.02);
  TrialRecord clean;
  GappyEngine reference(Configuration{}, true);
  reference.run_trial(paper, clean);
  const double clean_end_s = reference.trial_end_s();
  ASSERT_TRUE(clean.complete);

  GappyEngine e(Configuration{}, true);
  ASSERT_FALSE(e.device.time_follows_ticks());
  const int missed = e.config.safety.stale_ticks - 1;  // 35 ms: the longest late wake-up that rides through
  TrialRecord record;
  e.run_trial(paper, record, 600, missed);
  ASSERT_TRUE(record.complete) << "faulted: " << fault_name(e.core.fault());
  EXPECT_EQ(e.core.state(), EngineState::kArmed);
  EXPECT_EQ(e.core.held_ticks(), static_cast<std::uint64_t>(missed));  // the reading after it is fresh
  EXPECT_EQ(e.core.missed_deadline_warnings(), 0u);                    // a rig's: no warnings, a ride-through
  // The samples in the missed periods are held (at least one of 7 ticks, 4 ticks a sample), not learned from.
  EXPECT_GE(record.held_samples, missed / e.config.timing.ticks_per_sample);
  for (int k = 0; k <= paper.learning_samples(); ++k) {
    if (record.held[static_cast<std::size_t>(k)] != 0) {
      EXPECT_EQ(record.joint_samples(0).error_rad(k), 0.0) << k;
    }
  }
  // The trial's clock kept the rig's time: it ends when the clean one did, not `missed` ticks later.
  EXPECT_NEAR(e.trial_end_s(), clean_end_s, 1e-9);
  EXPECT_NEAR(record.rms_error_deg(), clean.rms_error_deg(), 0.15 * clean.rms_error_deg());
}

TEST(EngineLateLoop, ALateWakeUpAsLongAsTheStaleLimitVentsAndFaultsInTheTickItWakesIn) {
  GappyEngine e(Configuration{}, true);
  const int limit = e.config.safety.stale_ticks;
  TrialRecord record;
  e.run_trial(library_trajectory("paper", 0.02), record, 600, limit);
  ASSERT_EQ(e.core.state(), EngineState::kFault);
  EXPECT_EQ(e.core.fault(), FaultCode::kMissedDeadlines);
  EXPECT_FALSE(record.complete);
  bool fault_seen = false;
  for (const EngineEvent& event : e.drain()) {
    if (event.kind != EventKind::kFault) continue;
    fault_seen = true;
    EXPECT_NE(std::strstr(event.detail.data(),
                          "the rig went 40 ms without the loop's commands, 40 ms of it because the loop was late"),
              nullptr)
        << event.detail.data();
  }
  EXPECT_TRUE(fault_seen);
  TickRecord tick;
  e.core.read_snapshot(tick);
  EXPECT_EQ(tick.state, EngineState::kFault);
  EXPECT_EQ(tick.valves.joint[0].outlet_duty[0], 1.0);  // vented in the tick it woke in
  EXPECT_EQ(tick.valves.joint[0].inlet_duty[0], 0.0);
}

TEST(EngineLateLoop, MissedPeriodsAndMissingReadingsAddUpToTheStaleLimitNamedByTheLargerPart) {
  const int limit = SafetyParameters{}.stale_ticks;
  struct Case {
    int lost, missed;
    FaultCode named;
  };
  // Mostly the loop's lateness: missed-deadlines; mostly the link's silence: the device's word.
  for (const Case c :
       {Case{limit / 2, limit - limit / 2, FaultCode::kMissedDeadlines}, Case{limit - 2, 2, FaultCode::kSensorStale}}) {
    GappyEngine e(Configuration{}, true);
    EXPECT_TRUE(e.core.send(EngineCommand::of(CommandKind::kArm)));
    e.clock.step(20);
    e.device.lose_readings(e.device.reads(), c.lost);
    e.clock.step(c.lost);
    ASSERT_EQ(e.core.state(), EngineState::kArmed) << c.lost << " readings lost are below the limit";
    e.step_late(c.missed);  // the reading after the gap is fresh, but the rig went `limit` ticks without control
    EXPECT_EQ(e.core.state(), EngineState::kFault) << c.lost << " + " << c.missed;
    EXPECT_EQ(e.core.fault(), c.named) << c.lost << " + " << c.missed;
  }
  // One tick less of either: rides through.
  GappyEngine e(Configuration{}, true);
  EXPECT_TRUE(e.core.send(EngineCommand::of(CommandKind::kArm)));
  e.clock.step(20);
  e.device.lose_readings(e.device.reads(), limit / 2);
  e.clock.step(limit / 2);
  e.step_late(limit - limit / 2 - 1);
  e.clock.step(20);
  EXPECT_EQ(e.core.state(), EngineState::kArmed);
}

TEST(FaultVocabulary, EveryCodeHasAStableNameAndASentence) {
  std::set<std::string> names;
  for (int code = 0; code <= static_cast<int>(kLastFaultCode); ++code) {
    const std::string name = fault_name(static_cast<FaultCode>(code));
    EXPECT_NE(name, "unknown") << code;
    EXPECT_TRUE(names.insert(name).second) << name << " twice";
    EXPECT_STRNE(fault_message(static_cast<FaultCode>(code)), "unknown fault");
  }
  // The numbers are on the wire (telemetry_t.fault) and in black boxes: appended, never renumbered.
  EXPECT_EQ(static_cast<int>(FaultCode::kHeartbeatLost), 9);
  EXPECT_STREQ(fault_name(static_cast<FaultCode>(10)), "link-lost");
  EXPECT_STREQ(fault_name(static_cast<FaultCode>(11)), "rig-limit");
  EXPECT_STREQ(fault_name(static_cast<FaultCode>(15)), "foreign-sender");
  EXPECT_STREQ(fault_name(static_cast<FaultCode>(16)), "rig-unavailable");
}

TEST(FaultVocabulary, ADeviceFaultsTextIsTruncatedToFit) {
  DeviceFault f;
  const std::string long_text(500, 'x');
  f.set(FaultCode::kLinkLost, -1, "%s", long_text.c_str());
  EXPECT_EQ(std::strlen(f.text.data()), kFaultDetailChars - 1);
}

}  // namespace
}  // namespace bellows
