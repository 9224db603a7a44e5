// The console's Rig screen: the inputs, the valve test through the engine (asks first, every valve
// judged, verdicts in the log, Space stops it), and the device's link health in the header.
#include <gtest/gtest.h>

#include "tests/console_fixture.hpp"
#include "ui/render.hpp"

namespace bellows {
namespace {

using testing::ConsoleFixture;

std::string screen_of(const ui::ConsoleState& s) {
  std::string text;
  for (const std::string& line : ui::render_lines(s)) text += line + "\n";
  return text;
}

bool valve_test_done(ConsoleFixture& f) {
  return f.pump_until([&] { return !f.state().rig.valves.empty() && !f.state().rig.test_running; }, 60.0);
}

TEST(RigScreen, ShowsTheInputsAndSaysTheSimulatedArmHasNoVolts) {
  ConsoleFixture f;
  f.pump_for(0.5);
  f.key('b');
  EXPECT_EQ(f.state().screen, ui::Screen::kRig);
  const std::string screen = screen_of(f.state());
  EXPECT_NE(screen.find("Inputs: sim"), std::string::npos) << screen;
  EXPECT_NE(screen.find("no volts"), std::string::npos) << screen;
  EXPECT_NE(screen.find("supply"), std::string::npos) << screen;
  EXPECT_NE(screen.find("v starts it"), std::string::npos) << screen;
}

TEST(RigScreen, TheValveTestAsksFirstThenPassesEveryValveOfAHealthyArm) {
  ConsoleFixture f;
  f.pump_for(0.5);
  f.key('b');
  f.key('v');
  ASSERT_EQ(f.state().dialog.kind, ui::DialogKind::kConfirmValveTest);
  f.key('n');
  EXPECT_EQ(f.state().engine_state, EngineState::kSafe);
  EXPECT_TRUE(f.state().rig.valves.empty()) << "cancelled: nothing ran";
  f.key('v');
  f.key('y');
  ASSERT_TRUE(valve_test_done(f));
  for (const auto& line : f.state().rig.valves) EXPECT_TRUE(line.pass) << line.valve << ": " << line.text;
  EXPECT_TRUE(f.logged("valve test: inlet A pass"));
  EXPECT_TRUE(f.logged("valve test: outlet B pass"));
  EXPECT_NE(f.state().status.find("every valve passed"), std::string::npos) << f.state().status;
  ASSERT_TRUE(f.pump_until([&] { return f.state().engine_state == EngineState::kSafe; }));
  const std::string screen = screen_of(f.state());
  EXPECT_NE(screen.find("inlet A   pass"), std::string::npos) << screen;
}

TEST(RigScreen, SwappedWiringFailsEveryValveAndSaysSo) {
  Configuration c;
  c.plant.fault = "swapped-chambers";
  ConsoleFixture f(c);
  f.pump_for(0.5);
  f.key('b');
  f.key('v');
  f.key('y');
  ASSERT_TRUE(valve_test_done(f));
  for (const auto& line : f.state().rig.valves) {
    EXPECT_FALSE(line.pass) << line.valve;
    EXPECT_NE(line.text.find("swapped"), std::string::npos) << line.text;
  }
  EXPECT_TRUE(f.logged("valve test: inlet A FAIL"));
  EXPECT_TRUE(f.state().status_important);
}

TEST(RigScreen, SpaceStopsTheValveTestAndVents) {
  ConsoleFixture f;
  f.pump_for(0.5);
  f.key('b');
  f.key('v');
  f.key('y');
  ASSERT_TRUE(f.pump_until([&] { return f.state().engine_state == EngineState::kArmed; }));
  f.key(' ');
  ASSERT_TRUE(f.pump_until([&] { return f.state().engine_state == EngineState::kFault; }));
  EXPECT_FALSE(f.state().rig.test_running);
  EXPECT_NE(f.state().rig.test_progress.find("emergency stop"), std::string::npos) << f.state().rig.test_progress;
  EXPECT_NE(f.state().rig.valves.back().text.find("not tested"), std::string::npos);
}

TEST(RigScreen, TheHeaderShowsTheDevicesLink) {
  Configuration c;
  SimulatedArm arm(c.plant, 1);
  EngineCore core(arm, c.controller, c.timing, c.safety);
  SimulatedClock clock(core, arm);
  DeviceHealth link;
  link.has_link = true;
  link.connected = true;
  link.round_trip_p99_ms = 1.25;
  link.exchanges = 100;
  link.link_errors = 2;
  link.stale_readings = 7;
  ui::ConsoleEnvironment env;
  env.core = &core;
  env.config = c;
  env.device_name = "lcm";
  env.device_health = [&link] { return link; };
  env.load_trajectory = [c](const std::string& name) {
    return resolve_trajectory(name, c.timing.sample_s(), c.trajectory);
  };
  env.clock_text = [] { return std::string("12:00:00"); };
  ui::ConsoleController console(env, library_trajectory("paper", c.timing.sample_s()), false);
  console.resize(160, 40);
  console.start(0.0);
  clock.step(5);
  console.update(clock.now_s());
  EXPECT_EQ(console.state().device.status, "ok, rt p99 1.2 ms, 2 err, 7 stale");
  EXPECT_NE(screen_of(console.state()).find("device lcm: ok, rt p99 1.2 ms"), std::string::npos);
  link.connected = false;
  clock.step(100);  // past the refresh period
  console.update(1.0);
  EXPECT_FALSE(console.state().device.ok);
  EXPECT_NE(console.state().device.status.find("link lost"), std::string::npos) << console.state().device.status;
}

}  // namespace
}  // namespace bellows
