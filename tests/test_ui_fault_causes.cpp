// Every guard's fault, injected, reaches the console's event log and the saved session under its
// own name (never as "emergency stop"), with its black box.
#include <cmath>
#include <limits>

#include <gtest/gtest.h>

#include "devices/simulated_arm.hpp"
#include "tests/console_fixture.hpp"

namespace bellows::ui {
namespace {

using testing::ConsoleFixture;

/// The simulated arm, with its readings tampered with on demand to trip one guard; its time is
/// its own (like a rig's), so missed deadlines fault too.
class TamperedArm final : public Device {
 public:
  explicit TamperedArm(const Configuration& c) : arm_(c.plant, 1) {}
  SensorReading read_sensors() override {
    SensorReading r = arm_.read_sensors();
    switch (fault) {
      case FaultCode::kAngleLimit:
        r.joint[0].angle_rad = 100.0 * M_PI / 180.0;
        break;
      case FaultCode::kOverpressure:
        r.joint[0].chamber_bar[0] = 3.0;
        break;
      case FaultCode::kSupplyLow:
        r.supply_bar = 1.0;
        break;
      case FaultCode::kSensorNotANumber:
        r.joint[0].angle_rad = std::numeric_limits<double>::quiet_NaN();
        break;
      case FaultCode::kSensorOutOfRange:
        r.supply_bar = 50.0;
        break;
      case FaultCode::kSensorStale:
        r.time_s = frozen_time_s;
        break;
      default:
        break;
    }
    if (fault != FaultCode::kSensorStale) frozen_time_s = r.time_s;
    return r;
  }
  void write_valves(const ValveCommand& c) override { arm_.write_valves(c); }
  void vent() override { arm_.vent(); }
  void advance(double dt_s) override { arm_.advance(dt_s); }
  const char* name() const override { return "sim"; }
  FaultCode fault = FaultCode::kNone;
  double frozen_time_s = 0.0;

 private:
  SimulatedArm arm_;
};

class GuardFault : public ::testing::TestWithParam<FaultCode> {};

TEST_P(GuardFault, ReachesTheLogAndTheSessionUnderItsOwnName) {
  const FaultCode code = GetParam();
  const Configuration config;
  TamperedArm device(config);
  ConsoleFixture f(config, 3, nullptr, &device);
  f.arm_valves();
  f.key('r');  // a trial, so that the session exists before the fault
  ASSERT_TRUE(f.pump_until([&] { return f.idle(); }));
  ASSERT_EQ(f.state().experiment.trials.size(), 1u);

  switch (code) {
    case FaultCode::kEmergencyStop:
      f.key(' ');
      break;
    case FaultCode::kMissedDeadlines:
      for (int i = 0; i < config.safety.missed_deadline_streak + 1; ++i) {
        f.core.tick(f.clock.now_s() + i * config.timing.tick_s, f.clock.now_s(), 1);
        device.advance(config.timing.tick_s);
      }
      break;
    case FaultCode::kHeartbeatLost:
      f.clock.step(static_cast<long>(2.0 * config.safety.heartbeat_timeout_s / config.timing.tick_s));
      break;
    default:
      device.fault = code;
      break;
  }
  ASSERT_TRUE(f.pump_until([&] { return f.state().engine_state == EngineState::kFault; }, 5.0));
  EXPECT_EQ(f.core.fault(), code);
  const std::string name = fault_name(code);
  EXPECT_TRUE(f.logged(std::string("FAULT ") + name)) << name;
  EXPECT_TRUE(f.logged(std::string("-> FAULT (") + name + ")")) << name;
  if (code != FaultCode::kEmergencyStop) {
    EXPECT_FALSE(f.logged("(emergency stop)")) << name;
  }

  // Saved as it goes: the black box and the log lines, under the fault's name. The save runs on its
  // own thread while the pump advances engine time flat out: on a loaded machine 5 engine seconds
  // pass before it is scheduled, so the pump's default bound applies.
  ASSERT_TRUE(f.pump_until([&] { return f.console->saves_settled() && !f.state().experiment.faults.empty(); }));
  const SessionSnapshot& saved = f.sessions.saved.begin()->second;
  ASSERT_EQ(saved.experiment.faults.size(), 1u);
  EXPECT_EQ(saved.experiment.faults[0].fault, name);
  EXPECT_FALSE(saved.experiment.faults[0].ticks.empty());
  bool in_session_log = false;
  for (const LogEntry& e : saved.events) in_session_log = in_session_log || e.text.find("FAULT " + name) == 0;
  EXPECT_TRUE(in_session_log) << name;
}

INSTANTIATE_TEST_SUITE_P(EveryGuard, GuardFault,
                         ::testing::Values(FaultCode::kEmergencyStop, FaultCode::kAngleLimit, FaultCode::kOverpressure,
                                           FaultCode::kSupplyLow, FaultCode::kSensorNotANumber,
                                           FaultCode::kSensorOutOfRange, FaultCode::kSensorStale,
                                           FaultCode::kMissedDeadlines, FaultCode::kHeartbeatLost),
                         [](const ::testing::TestParamInfo<FaultCode>& param) {
                           std::string n = fault_name(param.param);
                           for (char& ch : n) ch = ch == '-' ? '_' : ch;
                           return n;
                         });

}  // namespace
}  // namespace bellows::ui
