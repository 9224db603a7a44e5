// The emergency stop is a latch the tick checks first: whatever the command queue holds, the next
// tick vents and faults with cause emergency-stop; it can be set from any thread (and from a signal
// handler), and a reset sent before a stop never undoes it. Missed deadlines on a device whose
// time follows the ticks are counted warnings; elsewhere they fault with advice.
#include <atomic>
#include <cstring>
#include <thread>

#include <gtest/gtest.h>

#include "engine_fixture.hpp"
#include "engine/control/safety.hpp"
#include "tests/test_support.hpp"

namespace bellows {
namespace {

using testing::EngineFixture;

/// A device that records what the engine wrote; its time passes on its own (a real rig's default).
class RecordingDevice final : public Device {
 public:
  SensorReading read_sensors() override {
    SensorReading r;
    r.time_s = ++reads * 0.005;
    r.joint[0].chamber_bar = {1.2, 1.2};
    r.supply_bar = 6.0;
    r.temperature_K = 293.0;
    return r;
  }
  void write_valves(const ValveCommand& c) override {
    last = c;
    ++writes;
  }
  void vent() override {
    last = ValveCommand::vented();
    ++vents;
  }
  void advance(double) override {}
  const char* name() const override { return "recording"; }
  ValveCommand last{};
  int reads = 0, writes = 0, vents = 0;
};

using testing::vented;

TEST(EmergencyStop, VentsInTheNextTickWhateverTheQueueHolds) {
  EngineFixture f;
  ASSERT_TRUE(f.core.send(EngineCommand::of(CommandKind::kArm)));
  f.clock.step(2);
  ASSERT_EQ(f.core.state(), EngineState::kArmed);
  // Fill the command queue with anything: heartbeats, gains.
  int queued = 0;
  EngineCommand gains = EngineCommand::of(CommandKind::kSetGains);
  gains.gains = {0.1, 0.2, 0.0, 0.0};
  while (f.core.send(queued % 2 == 0 ? EngineCommand::of(CommandKind::kHeartbeat) : gains)) ++queued;
  EXPECT_GE(queued, 100);
  EXPECT_FALSE(f.core.send(EngineCommand::of(CommandKind::kHeartbeat)));  // full: refused, and said so
  // The stop is not queued: it always goes through.
  EXPECT_TRUE(f.core.send(EngineCommand::of(CommandKind::kEmergencyStop)));
  EXPECT_FALSE(f.core.emergency_stop_delivered());
  f.clock.step(1);
  EXPECT_TRUE(f.core.emergency_stop_delivered());
  EXPECT_EQ(f.core.state(), EngineState::kFault);
  EXPECT_EQ(f.core.fault(), FaultCode::kEmergencyStop);
  EXPECT_TRUE(vented(f.snapshot().valves));
  bool fault_event = false;
  for (const EngineEvent& e : f.drain_events()) {
    if (e.kind == EventKind::kFault) fault_event = e.fault == FaultCode::kEmergencyStop;
  }
  EXPECT_TRUE(fault_event);
}

TEST(EmergencyStop, FromAnotherThreadWhileTheOperatorThreadIsBlocked) {
  RecordingDevice device;
  const Configuration c;
  EngineCore core(device, c.controller, c.timing, c.safety);
  SimulatedClock clock(core, device);
  ASSERT_TRUE(core.send(EngineCommand::of(CommandKind::kArm)));
  clock.step(2);
  ASSERT_EQ(core.state(), EngineState::kArmed);
  while (core.send(EngineCommand::of(CommandKind::kHeartbeat))) {
  }
  // The operator thread is blocked (it never runs again in this test); a watchdog thread stops.
  std::atomic<bool> requested{false};
  std::thread other([&] {
    core.request_emergency_stop();
    requested = true;
  });
  other.join();
  ASSERT_TRUE(requested);
  const int vents_before = device.vents;
  clock.step(1);  // the loop's next tick
  EXPECT_EQ(core.state(), EngineState::kFault);
  EXPECT_EQ(core.fault(), FaultCode::kEmergencyStop);
  EXPECT_GT(device.vents, vents_before);
  EXPECT_TRUE(vented(device.last));
}

TEST(EmergencyStop, AResetSentBeforeTheStopDoesNotUndoIt) {
  EngineFixture f;
  ASSERT_TRUE(f.core.send(EngineCommand::of(CommandKind::kEmergencyStop)));
  f.clock.step(1);
  ASSERT_EQ(f.core.state(), EngineState::kFault);
  f.drain_events();
  // The operator resets, then stops again before the engine took the reset.
  ASSERT_TRUE(f.core.send(EngineCommand::of(CommandKind::kReset)));
  f.core.request_emergency_stop();
  f.clock.step(2);
  EXPECT_EQ(f.core.state(), EngineState::kFault);
  bool refused = false;
  for (const EngineEvent& e : f.drain_events()) {
    refused = refused || (e.kind == EventKind::kCommandRefused && e.command == CommandKind::kReset);
  }
  EXPECT_TRUE(refused);
  // A reset sent after the stop works.
  ASSERT_TRUE(f.core.send(EngineCommand::of(CommandKind::kReset)));
  f.clock.step(1);
  EXPECT_EQ(f.core.state(), EngineState::kSafe);
}

TEST(FaultCause, AGuardsStateChangeNamesTheGuardNotAnEmergencyStop) {
  EngineFixture f;
  ASSERT_TRUE(f.core.send(EngineCommand::of(CommandKind::kArm)));
  f.clock.step(2);
  f.drain_events();
  f.arm.inject_fault(SimulatedFault::kNanAngle);
  f.clock.step(3);
  ASSERT_EQ(f.core.fault(), FaultCode::kSensorNotANumber);
  bool named = false;
  for (const EngineEvent& e : f.drain_events()) {
    if (e.kind == EventKind::kStateChanged && e.to == EngineState::kFault) {
      EXPECT_EQ(e.fault, FaultCode::kSensorNotANumber);
      EXPECT_NE(e.command, CommandKind::kEmergencyStop);
      named = true;
    }
  }
  EXPECT_TRUE(named);
}

TEST(MissedDeadlines, OnTheSimulatedArmAreCountedWarningsNotAFault) {
  EngineFixture f;  // SimulatedArm: its time follows the ticks
  ASSERT_TRUE(f.arm.time_follows_ticks());
  ASSERT_TRUE(f.core.send(EngineCommand::of(CommandKind::kArm)));
  f.clock.step(2);
  f.drain_events();
  for (int i = 0; i < 20; ++i) {
    f.core.tick(1.0 + i * 0.005, 1.0 + i * 0.005, 3);
    f.arm.advance(0.005);
  }
  EXPECT_EQ(f.core.state(), EngineState::kArmed);
  EXPECT_EQ(f.core.missed_deadline_warnings(), 60u);
  int warnings = 0;
  for (const EngineEvent& e : f.drain_events()) {
    if (e.kind == EventKind::kWarning && e.fault == FaultCode::kMissedDeadlines) ++warnings;
  }
  EXPECT_EQ(warnings, 1);  // one per streak, not one per tick
}

TEST(MissedDeadlines, OnADeviceWithItsOwnTimeFaultWithAdvice) {
  RecordingDevice device;
  ASSERT_FALSE(device.time_follows_ticks());
  const Configuration c;
  EngineCore core(device, c.controller, c.timing, c.safety);
  ASSERT_TRUE(core.send(EngineCommand::of(CommandKind::kArm)));
  core.tick(0.0, 0.0, 0);
  ASSERT_EQ(core.state(), EngineState::kArmed);
  for (int i = 1; i <= c.safety.missed_deadline_streak && core.state() != EngineState::kFault; ++i) {
    core.tick(i * 0.005, i * 0.005, 1);
  }
  EXPECT_EQ(core.fault(), FaultCode::kMissedDeadlines);
  EXPECT_EQ(core.missed_deadline_warnings(), 0u);
  const std::string message = fault_message(FaultCode::kMissedDeadlines);
  EXPECT_NE(message.find("[safety] missed_deadline_streak"), std::string::npos);
  EXPECT_NE(message.find("--rt"), std::string::npos);
  EXPECT_NE(message.find("load"), std::string::npos);
}

TEST(EngineCore, HandsTrajectoriesBack) {
  EngineFixture f;
  const Trajectory a = library_trajectory("steps", f.config.timing.sample_s());
  const Trajectory b = library_trajectory("sine", f.config.timing.sample_s());
  ASSERT_TRUE(f.core.send(EngineCommand::select_trajectory(a)));
  ASSERT_TRUE(f.core.send(EngineCommand::select_trajectory(b)));
  f.clock.step(1);
  std::vector<const Trajectory*> held;
  for (const EngineEvent& e : f.drain_events()) {
    if (e.kind == EventKind::kTrajectorySelected) held.push_back(e.trajectory);
  }
  ASSERT_EQ(held.size(), 2u);
  EXPECT_EQ(held[0], &a);
  EXPECT_EQ(held[1], &b);
}

}  // namespace
}  // namespace bellows
