// The engine on a simulated clock: arming, refusals, the fault latch, every guard against an
// injected fault, the black box, heartbeats and missed deadlines.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "tests/engine_fixture.hpp"
#include "tests/test_support.hpp"

namespace bellows {
namespace {

using testing::EngineFixture;

using testing::vented;

TEST(EngineCore, StartsSafeAndVentedAndArmsOnlyOnCommand) {
  EngineFixture f;
  for (int i = 0; i < 100; ++i) {
    f.clock.step();
    EXPECT_EQ(f.core.state(), EngineState::kSafe);
    EXPECT_TRUE(vented(f.snapshot().valves));
  }
  f.send(CommandKind::kArm);
  f.clock.step();
  EXPECT_EQ(f.core.state(), EngineState::kArmed);
  const auto events = f.drain_events();
  ASSERT_FALSE(events.empty());
  EXPECT_EQ(events.back().kind, EventKind::kStateChanged);
  EXPECT_EQ(events.back().to, EngineState::kArmed);
}

TEST(EngineCore, RefusesATrialWhileSafeAndSaysWhy) {
  EngineFixture f;
  const Trajectory paper = library_trajectory("paper", 0.02);
  Eigen::VectorXd correction = Eigen::VectorXd::Zero(paper.learning_samples());
  TrialRecord record;
  record.prepare(paper.learning_samples(), 4);
  const EngineCommand start = EngineCommand::start_trial(paper, correction, record, 0, 1);
  EXPECT_TRUE(f.core.send(start));
  f.clock.step(10);
  EXPECT_EQ(f.core.state(), EngineState::kSafe);
  const auto events = f.drain_events();
  ASSERT_EQ(events.size(), 1u);
  EXPECT_EQ(events[0].kind, EventKind::kCommandRefused);
  EXPECT_STREQ(events[0].refusal, "arm the valves first");
}

TEST(EngineCore, RefusesATrialWhoseRecordIsNotPrepared) {
  EngineFixture f;
  const Trajectory paper = library_trajectory("paper", 0.02);
  Eigen::VectorXd correction = Eigen::VectorXd::Zero(paper.learning_samples());
  TrialRecord record;  // not prepared: the loop would have to allocate
  f.send(CommandKind::kArm);
  f.clock.step();
  const EngineCommand start = EngineCommand::start_trial(paper, correction, record, 0, 1);
  f.drain_events();
  EXPECT_TRUE(f.core.send(start));
  f.clock.step();
  EXPECT_EQ(f.core.state(), EngineState::kArmed);
  const auto events = f.drain_events();
  ASSERT_EQ(events.size(), 1u);
  EXPECT_EQ(events[0].kind, EventKind::kCommandRefused);
}

TEST(EngineCore, FaultLatchesUntilResetAndResetNeedsAFreshArm) {
  EngineFixture f;
  f.send(CommandKind::kArm);
  f.clock.step(50);
  f.send(CommandKind::kEmergencyStop);
  f.clock.step();
  EXPECT_EQ(f.core.state(), EngineState::kFault);
  EXPECT_EQ(f.core.fault(), FaultCode::kEmergencyStop);
  f.send(CommandKind::kArm);  // arming alone does not clear a fault
  f.clock.step(5);
  EXPECT_EQ(f.core.state(), EngineState::kFault);
  f.send(CommandKind::kReset);
  f.clock.step();
  EXPECT_EQ(f.core.state(), EngineState::kSafe);  // not armed: valves stay vented
  EXPECT_TRUE(vented(f.snapshot().valves));
  EXPECT_EQ(f.core.fault(), FaultCode::kNone);
  f.send(CommandKind::kArm);
  f.clock.step();
  EXPECT_EQ(f.core.state(), EngineState::kArmed);
}

/// A trial of the paper trajectory with no correction, armed and sent as trial `trial_id`.
struct PaperTrial {
  Trajectory paper = library_trajectory("paper", 0.02);
  Eigen::VectorXd correction = Eigen::VectorXd::Zero(paper.learning_samples());
  TrialRecord record;
  PaperTrial(EngineFixture& f, std::uint32_t trial_id) {
    record.prepare(paper.learning_samples(), 4);
    f.send(CommandKind::kArm);
    f.clock.step();
    EXPECT_TRUE(f.core.send(EngineCommand::start_trial(paper, correction, record, 0, trial_id)));
  }
};

TEST(EngineCore, DisarmDuringATrialHandsTheRecordBack) {
  EngineFixture f;
  PaperTrial trial(f, 42);
  TrialRecord& record = trial.record;
  f.clock.step(100);
  EXPECT_EQ(f.core.state(), EngineState::kRunning);
  f.drain_events();
  f.send(CommandKind::kDisarm);
  f.clock.step();
  EXPECT_EQ(f.core.state(), EngineState::kSafe);
  const auto events = f.drain_events();
  ASSERT_GE(events.size(), 2u);
  EXPECT_EQ(events[0].kind, EventKind::kTrialAborted);
  EXPECT_EQ(events[0].record, &record);
  EXPECT_EQ(events[0].trial_id, 42u);
  EXPECT_FALSE(record.complete);
}

TEST(EngineCore, ATrialsEndIsReportedAsItsOwnCauseNotAsTheStartCommand) {
  EngineFixture f;
  PaperTrial trial(f, 7);
  const TrialRecord& record = trial.record;
  std::vector<EngineEvent> events;
  for (int i = 0; i < 20000 && !record.complete; ++i) {
    f.clock.step();
    for (const EngineEvent& e : f.drain_events()) events.push_back(e);
  }
  f.clock.step();
  for (const EngineEvent& e : f.drain_events()) events.push_back(e);
  ASSERT_TRUE(record.complete);
  EXPECT_EQ(f.core.state(), EngineState::kArmed);
  int starts = 0, ends = 0;
  for (const EngineEvent& e : events) {
    if (e.kind != EventKind::kStateChanged) continue;
    if (e.from == EngineState::kArmed && e.to == EngineState::kRunning) {
      ++starts;
      EXPECT_EQ(e.command, CommandKind::kStartTrial);
    }
    if (e.from == EngineState::kRunning && e.to == EngineState::kArmed) {
      ++ends;
      EXPECT_EQ(e.command, CommandKind::kTrialEnd) << to_string(e.command);
      EXPECT_STREQ(to_string(e.command), "trial complete");
    }
  }
  EXPECT_EQ(starts, 1);
  EXPECT_EQ(ends, 1);
  EXPECT_FALSE(transition(EngineState::kRunning, CommandKind::kTrialEnd).allowed);  // a cause, never a command
}

// Arms, holds for a second, injects `fault` and runs until the engine faults.
struct FaultRun {
  std::uint64_t fault_tick = 0;
  std::vector<TickRecord> black_box;
};

FaultRun run_until_fault(EngineFixture& f, SimulatedFault fault) {
  f.send(CommandKind::kArm);
  f.clock.step(500);  // longer than the black box, so it holds only armed ticks before the fault
  EXPECT_EQ(f.core.state(), EngineState::kArmed) << fault_name(f.core.fault());
  f.arm.inject_fault(fault);
  for (int i = 0; i < 2000 && f.core.state() != EngineState::kFault; ++i) f.clock.step();
  EXPECT_EQ(f.core.state(), EngineState::kFault);
  FaultRun run;
  run.fault_tick = f.core.ticks() - 1;
  run.black_box = f.core.black_box().copy_frozen();
  return run;
}

struct FaultCase {
  SimulatedFault injected;
  FaultCode expected;
};

class InjectedFault : public ::testing::TestWithParam<FaultCase> {};

TEST_P(InjectedFault, FaultsWithinOneTickOfVisibilityVentsAndKeepsTheBlackBox) {
  EngineFixture f;
  const FaultRun run = run_until_fault(f, GetParam().injected);
  EXPECT_EQ(f.core.fault(), GetParam().expected) << fault_name(f.core.fault());

  // The black box: the ticks before the fault (2 s of them), ending with the fault tick.
  const auto& box = run.black_box;
  ASSERT_EQ(box.size(), f.core.black_box().capacity());
  EXPECT_EQ(box.back().tick, run.fault_tick);
  EXPECT_EQ(box.back().state, EngineState::kFault);
  for (std::size_t i = 0; i + 1 < box.size(); ++i) {
    EXPECT_EQ(box[i + 1].tick, box[i].tick + 1);
    EXPECT_EQ(box[i].state, EngineState::kArmed);
  }

  // Visible means: the guards, fed that tick's reading, name the fault. The tick before, they did not.
  const SafetyParameters& limits = f.config.safety;
  auto stale_count_at = [&](std::size_t index) {
    int stale = 0;
    for (std::size_t i = index; i > 0 && box[i].reading.time_s <= box[i - 1].reading.time_s; --i) ++stale;
    return stale;
  };
  auto guards_at = [&](std::size_t index) {
    GuardInputs inputs;
    inputs.p_max_bar = f.config.controller.p_max_bar;
    inputs.stale_count = stale_count_at(index);
    return check_guards(box[index].reading, inputs, limits);
  };
  EXPECT_EQ(guards_at(box.size() - 1), GetParam().expected);
  EXPECT_EQ(guards_at(box.size() - 2), FaultCode::kNone);

  // Vented from the fault tick on: the tick's command, the device, and every tick after.
  EXPECT_TRUE(vented(box.back().valves));
  for (int i = 0; i < 200; ++i) {
    f.clock.step();
    EXPECT_TRUE(vented(f.snapshot().valves));
    EXPECT_TRUE(vented(f.arm.state().command));
    EXPECT_EQ(f.core.state(), EngineState::kFault);
  }
  // The black box stays frozen on the fault while the engine keeps ticking.
  EXPECT_EQ(f.core.black_box().copy_frozen().back().tick, run.fault_tick);
}

INSTANTIATE_TEST_SUITE_P(
    EveryGuard, InjectedFault,
    ::testing::Values(FaultCase{SimulatedFault::kSensorDropout, FaultCode::kSensorStale},
                      // The arm swings toward A past its limit before chamber A exceeds p_max + margin.
                      FaultCase{SimulatedFault::kStuckInlet, FaultCode::kAngleLimit},
                      FaultCase{SimulatedFault::kSupplyLoss, FaultCode::kSupplyLow},
                      FaultCase{SimulatedFault::kNanAngle, FaultCode::kSensorNotANumber},
                      FaultCase{SimulatedFault::kPressureSpike, FaultCode::kOverpressure}),
    [](const auto& test_info) {
      std::string name = to_string(test_info.param.injected);
      std::erase(name, '-');
      return name;
    });

TEST(EngineCore, StuckInletIsCaughtBeforeThePressureRunsAway) {
  EngineFixture f;
  run_until_fault(f, SimulatedFault::kStuckInlet);
  const double limit = f.config.controller.p_max_bar + f.config.safety.pressure_margin_bar;
  EXPECT_LT(f.arm.state().chamber_Pa[0] / 1e5, limit + 0.1);
}

TEST(EngineCore, AngleBeyondItsLimitFaults) {
  EngineFixture f;
  f.send(CommandKind::kArm);
  f.clock.step(20);
  SimulatedArm::State s = f.arm.state();
  s.angle_rad = 96.0 * std::numbers::pi / 180.0;
  f.arm.set_state(s);
  f.clock.step();
  EXPECT_EQ(f.core.fault(), FaultCode::kAngleLimit);
}

TEST(EngineCore, ImplausibleReadingFaultsAsOutOfRange) {
  EngineFixture f;
  f.send(CommandKind::kArm);
  f.clock.step(20);
  SimulatedArm::State s = f.arm.state();
  s.chamber_Pa[1] = 12e5;
  f.arm.set_state(s);
  f.clock.step();
  EXPECT_EQ(f.core.fault(), FaultCode::kSensorOutOfRange);
}

TEST(EngineCore, SilentConsoleFaultsAfterTheHeartbeatTimeout) {
  EngineFixture f;
  f.core.monitor_heartbeat(true);
  f.send(CommandKind::kArm);
  const int ticks_per_s = 200;
  for (int i = 0; i < 3 * ticks_per_s; ++i) {  // beating every 0.5 s: fine
    if (i % (ticks_per_s / 2) == 0) f.send(CommandKind::kHeartbeat);
    f.clock.step();
  }
  EXPECT_EQ(f.core.state(), EngineState::kArmed);
  const std::uint64_t silent_from = f.core.ticks();
  while (f.core.state() != EngineState::kFault && f.core.ticks() < silent_from + 1000) f.clock.step();
  EXPECT_EQ(f.core.fault(), FaultCode::kHeartbeatLost);
  const double silent_s = static_cast<double>(f.core.ticks() - silent_from) / ticks_per_s;
  EXPECT_NEAR(silent_s, f.config.safety.heartbeat_timeout_s - 0.5, 0.02);  // the last beat was 0.5 s before
}

/// The simulated arm as if its time were its own, like a rig's (missed deadlines then fault).
class ArmOnItsOwnTime final : public Device {
 public:
  explicit ArmOnItsOwnTime(SimulatedArm& arm) : arm_(arm) {}
  SensorReading read_sensors() override { return arm_.read_sensors(); }
  void write_valves(const ValveCommand& c) override { arm_.write_valves(c); }
  void vent() override { arm_.vent(); }
  void advance(double dt_s) override { arm_.advance(dt_s); }
  const char* name() const override { return "rig-like"; }

 private:
  SimulatedArm& arm_;
};

TEST(EngineCore, AStreakOfMissedDeadlinesFaults) {
  const Configuration c;
  SimulatedArm arm(c.plant, 1);
  ArmOnItsOwnTime rig(arm);
  EngineCore core(rig, c.controller, c.timing, c.safety);
  EXPECT_TRUE(core.send(EngineCommand::of(CommandKind::kArm)));
  double now = 0.0;
  auto tick = [&](int missed) {
    now += 0.005;
    core.tick(now, now, missed);
    rig.advance(0.005);
  };
  for (int i = 0; i < 10; ++i) tick(0);
  tick(1);  // isolated misses are tolerated
  tick(0);
  EXPECT_EQ(core.state(), EngineState::kArmed);
  for (int i = 0; i < c.safety.missed_deadline_streak - 1; ++i) tick(1);
  EXPECT_EQ(core.state(), EngineState::kArmed);
  tick(1);
  EXPECT_EQ(core.fault(), FaultCode::kMissedDeadlines);
}

TEST(EngineCore, ConfiguredFaultFiresAtItsTime) {
  Configuration c;
  c.plant.fault = "supply-loss";
  c.plant.fault_at_s = 1.5;
  EngineFixture f(c);
  f.send(CommandKind::kArm);
  f.clock.step(290);  // 1.45 s
  EXPECT_EQ(f.core.state(), EngineState::kArmed);
  f.clock.step(20);
  EXPECT_EQ(f.core.fault(), FaultCode::kSupplyLow);
  EXPECT_NEAR(f.core.black_box().copy_frozen().back().time_s, 1.5, 0.006);
}

TEST(EngineCore, GuardsStayQuietWhileSafe) {
  EngineFixture f;
  f.arm.inject_fault(SimulatedFault::kSupplyLoss);
  f.clock.step(100);
  EXPECT_EQ(f.core.state(), EngineState::kSafe);
  f.send(CommandKind::kArm);  // arming without supply faults at once
  f.clock.step();
  EXPECT_EQ(f.core.fault(), FaultCode::kSupplyLow);
}

}  // namespace
}  // namespace bellows
