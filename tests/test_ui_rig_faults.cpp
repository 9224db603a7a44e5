// A rig's own trip and a lost link reach the console under their own names, with the device's
// sentence (issue 25): the fault screen, the event log and the saved session's events and black box
// say `rig-limit` / `link-lost` and the rig's words, never `sensor-stale`. At the ui level, without
// processes: the device reports its faults as LcmDevice and T7Device do (Device::take_fault,
// Device::explain_silence); tests/test_lcm_rig_faults.cpp shows the same names in a run's JSON.
#include <gtest/gtest.h>

#include "devices/simulated_arm.hpp"
#include "tests/console_fixture.hpp"
#include "ui/render.hpp"

namespace bellows::ui {
namespace {

using testing::ConsoleFixture;

// The sentences LcmDevice gives (devices/lcm_device.cpp): the rig's trip, and a rig gone silent.
constexpr const char* kRigTrip =
    "the rig stopped joint 1 at -90.3 deg beyond its angle range ([lcm] rig_angle_limit_deg): check the chamber wiring "
    "(bellows rig check --device lcm pulses each chamber)";
constexpr const char* kSilence =
    "the LCM rig 5e1f0c has been silent for 41 ms (no state on BELLOWS_IO_STATE): check that the rig runs and the "
    "network to it";

/// The simulated arm as a rig over a link: on demand it trips (its own limit, reported once as a
/// device fault) or falls silent (its readings stop advancing: the engine's stale limit asks why).
class LinkedRig final : public Device {
 public:
  explicit LinkedRig(const Configuration& c) : arm_(c.plant, 1) {}
  SensorReading read_sensors() override {
    SensorReading r = arm_.read_sensors();
    if (silent) r.time_s = last_time_s_;
    last_time_s_ = r.time_s;
    return r;
  }
  void write_valves(const ValveCommand& c) override { arm_.write_valves(c); }
  void vent() override { arm_.vent(); }
  void advance(double dt_s) override { arm_.advance(dt_s); }
  const char* name() const override { return "lcm"; }
  bool take_fault(DeviceFault& fault) override {
    if (!trip || trip_reported_) return false;
    trip_reported_ = true;
    fault.set(FaultCode::kRigLimit, 0, "%s", kRigTrip);
    return true;
  }
  void explain_silence(double, DeviceFault& fault) const override {
    fault.set(FaultCode::kLinkLost, -1, "%s", kSilence);
  }

  bool trip = false;
  bool silent = false;

 private:
  SimulatedArm arm_;
  double last_time_s_ = 0.0;
  bool trip_reported_ = false;
};

std::string screen_text(const ConsoleState& s) {
  std::string text;
  for (const std::string& line : render_lines(s)) text += line + "\n";
  return text;
}

/// The text of the fault screen without the frame's line breaks (the sentence is wrapped).
std::string unwrapped_fault_screen(const ConsoleState& s) {
  std::string text;
  for (std::string line : render_lines(s)) {
    while (!line.empty() && line.back() == ' ') line.pop_back();
    const std::size_t first = line.find_first_not_of(' ');
    if (first != std::string::npos) text += line.substr(first) + " ";
  }
  return text;
}

struct Case {
  const char* name;
  FaultCode code;
  const char* sentence;
};

void PrintTo(const Case& c, std::ostream* out) { *out << c.name; }

class RigFaultOnTheConsole : public ::testing::TestWithParam<Case> {};

TEST_P(RigFaultOnTheConsole, TheFaultScreenTheLogAndTheSessionCarryItsNameAndTheRigsSentence) {
  const Case c = GetParam();
  const Configuration config;
  LinkedRig rig(config);
  ConsoleFixture f(config, 3, nullptr, &rig);
  f.arm_valves();
  f.key('r');  // a trial, so that the session exists before the fault
  ASSERT_TRUE(f.pump_until([&] { return f.idle(); }));
  f.key('r');  // the fault comes in the middle of the next one
  f.pump_for(1.0);
  if (c.code == FaultCode::kRigLimit) rig.trip = true;
  else rig.silent = true;
  ASSERT_TRUE(f.pump_until([&] { return f.state().engine_state == EngineState::kFault; }, 5.0));
  EXPECT_EQ(f.core.fault(), c.code);

  // The fault screen opens by itself: the name, then the device's sentence, whole.
  ASSERT_EQ(f.state().screen, Screen::kFault);
  EXPECT_EQ(f.state().fault_view.code, c.code);
  EXPECT_EQ(f.state().fault_view.detail, c.sentence);
  const std::string screen = screen_text(f.state());
  EXPECT_NE(screen.find(std::string(" ") + c.name + " "), std::string::npos) << screen;
  EXPECT_NE(unwrapped_fault_screen(f.state()).find(c.sentence), std::string::npos) << screen;
  EXPECT_EQ(screen.find("sensor-stale"), std::string::npos) << screen;

  // The event log, the status line.
  const std::string logged = std::string("FAULT ") + c.name + ": " + c.sentence;
  EXPECT_TRUE(f.logged(logged)) << logged;
  EXPECT_FALSE(f.logged("sensor-stale"));
  EXPECT_NE(f.state().status.find(std::string("FAULT ") + c.name), std::string::npos) << f.state().status;

  // The saved session: its events and its black box under the same name.
  ASSERT_TRUE(f.pump_until([&] { return f.console->saves_settled() && !f.state().experiment.faults.empty(); }));
  ASSERT_TRUE(f.pump_until([&] { return f.console->saves_settled(); }));
  ASSERT_FALSE(f.sessions.saved.empty());
  const SessionSnapshot& saved = f.sessions.saved.begin()->second;
  ASSERT_EQ(saved.experiment.faults.size(), 1u);
  EXPECT_EQ(saved.experiment.faults[0].fault, c.name);
  EXPECT_FALSE(saved.experiment.faults[0].ticks.empty());
  bool in_session_log = false;
  for (const LogEntry& e : saved.events) {
    in_session_log = in_session_log || e.text.find(logged) == 0;
    EXPECT_EQ(e.text.find("sensor-stale"), std::string::npos) << e.text;
  }
  EXPECT_TRUE(in_session_log) << logged;
}

INSTANTIATE_TEST_SUITE_P(TripAndSilence, RigFaultOnTheConsole,
                         ::testing::Values(Case{"rig-limit", FaultCode::kRigLimit, kRigTrip},
                                           Case{"link-lost", FaultCode::kLinkLost, kSilence}),
                         [](const ::testing::TestParamInfo<Case>& param) {
                           return param.param.code == FaultCode::kRigLimit ? std::string("RigTrip")
                                                                           : std::string("LinkLost");
                         });

}  // namespace
}  // namespace bellows::ui
