// `bellows rig check --device lcm`, the rig's own limits (app/rig_check_limits.hpp): the judges
// alone (every announced limit that differs from the configuration, every defect of a provoked
// timeout, each named), then over memq:// on the real-time loop, the rig server (io-sim's core)
// announcing its limits and its command timeout provoked, and the drill of a rig that never
// times out. tests/test_lcm_rig_faults.cpp runs the same check against io-sim as processes.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "app/rig_check_limits.hpp"
#include "devices/lcm_channels.hpp"
#include "devices/lcm_device.hpp"
#include "devices/lcm_rig_server.hpp"
#include "engine/rt/engine_core.hpp"
#include "engine/rt/realtime_loop.hpp"
#include "tests/lcm_bench.hpp"
#include "tests/lcm_test_support.hpp"

namespace bellows {
namespace {

RigAnnouncedLimits as_configured(const Configuration& c) {
  const RigLimits limits = RigLimits::from(c);
  return {1.0, 77, 1, c.timing.tick_s, c.lcm.rig_timeout_s, limits.pressure_ceiling_bar, limits.angle_limit_rad};
}

const LimitVerdict& verdict(const std::vector<LimitVerdict>& all, const std::string& name) {
  for (const LimitVerdict& v : all) {
    if (v.name == name) return v;
  }
  static const LimitVerdict none{"(missing)", "", "", "no such verdict"};
  return none;
}

/// Only `failing` fails, and its problem says `phrase`.
void expect_only_failure(const std::vector<LimitVerdict>& all, const std::string& failing, const std::string& phrase) {
  for (const LimitVerdict& v : all) {
    if (v.name == failing) {
      EXPECT_FALSE(v.pass()) << v.name;
      EXPECT_NE(v.problem.find(phrase), std::string::npos) << v.problem;
    } else {
      EXPECT_TRUE(v.pass()) << v.name << ": " << v.problem;
    }
  }
  EXPECT_NE(verdict(all, failing).name, "(missing)") << failing;
}

TEST(RigCheckLimits, ARigConfiguredFromTheEnginesNumbersPassesEveryAnnouncedLimit) {
  const Configuration c;
  const RigAnnouncedLimits a = as_configured(c);
  const std::vector<LimitVerdict> all = judge_announced_limits(&a, c, 1);
  ASSERT_EQ(all.size(), 5u);
  for (const LimitVerdict& v : all) EXPECT_TRUE(v.pass()) << v.name << ": " << v.problem;
  EXPECT_EQ(verdict(all, "pressure ceiling").found, "1.750 bar");
  EXPECT_EQ(verdict(all, "angle range").found, "100.0 deg");
  EXPECT_EQ(verdict(all, "command timeout").found, "50.0 ms");
}

TEST(RigCheckLimits, EachAnnouncedLimitThatDiffersIsNamedWithTheKeysToSet) {
  const Configuration c;
  RigAnnouncedLimits a = as_configured(c);
  a.pressure_ceiling_bar = 1.4;  // the rig's ceiling set to p_max, the margin forgotten (issue 25, question 4)
  expect_only_failure(judge_announced_limits(&a, c, 1), "pressure ceiling",
                      "at or below the engine's own guard 1.650 bar");
  a = as_configured(c);
  a.pressure_ceiling_bar = 2.2;  // above: not below the guard, but not what was planned
  expect_only_failure(judge_announced_limits(&a, c, 1), "pressure ceiling", "expects 1.750 bar");
  a = as_configured(c);
  a.angle_limit_rad = 90.0 * std::numbers::pi / 180.0;  // the lab's hardware stops inside the guard's 95
  expect_only_failure(judge_announced_limits(&a, c, 1), "angle range", "inside the engine's guard 95.0 deg");
  a = as_configured(c);
  a.angle_limit_rad = 120.0 * std::numbers::pi / 180.0;
  expect_only_failure(judge_announced_limits(&a, c, 1), "angle range", "set [lcm] rig_angle_limit_deg to the rig's");
  a = as_configured(c);
  a.command_timeout_s = 1.0;
  expect_only_failure(judge_announced_limits(&a, c, 1), "command timeout", "leaves the arm driven longer");
  a = as_configured(c);
  a.period_s = 0.01;
  expect_only_failure(judge_announced_limits(&a, c, 1), "state period", "every 10.00 ms");
  a = as_configured(c);
  a.joints = 2;
  expect_only_failure(judge_announced_limits(&a, c, 1), "joints", "an arm of 2 joints");
  const std::vector<LimitVerdict> none = judge_announced_limits(nullptr, c, 1);
  ASSERT_EQ(none.size(), 1u);
  EXPECT_NE(none[0].problem.find("announced no limits"), std::string::npos) << none[0].problem;
}

TimeoutObservation a_good_trip(const Configuration& c) {
  TimeoutObservation t;
  t.session_id = 11;
  t.last_command_seq = 500;
  t.tripped = true;
  t.delay_s = c.lcm.rig_timeout_s + 0.004;
  t.trip.session_id = 11;
  t.trip.command_seq = 500;
  t.trip.fault_bits = std::int32_t{io_state_t::FAULT_NO_SESSION} | std::int32_t{io_state_t::FAULT_COMMAND_TIMEOUT};
  t.before.joint[0].chamber_bar = {1.25, 1.24};
  t.after.joint[0].chamber_bar = {1.02, 1.02};
  t.served_again = true;
  t.engine_fault = FaultCode::kRigTimeout;
  return t;
}

TEST(RigCheckLimits, TheProvokedTimeoutPassesOnlyWhenTheRigTripsInTimeNamesTheSessionVentsAndServesAgain) {
  const Configuration c;
  EXPECT_TRUE(judge_command_timeout(a_good_trip(c), c).pass()) << judge_command_timeout(a_good_trip(c), c).problem;
  const auto fails_with = [&](const TimeoutObservation& t, const std::string& phrase) {
    const LimitVerdict v = judge_command_timeout(t, c);
    EXPECT_FALSE(v.pass()) << phrase;
    EXPECT_NE(v.problem.find(phrase), std::string::npos) << v.problem;
  };
  TimeoutObservation t = a_good_trip(c);
  t.tripped = false;
  t.silent_for_s = 0.175;
  fails_with(t, "did not vent by itself: no state with FAULT_COMMAND_TIMEOUT in 175 ms");
  t = a_good_trip(c);
  t.delay_s = 0.2;
  fails_with(t, "later than [lcm] rig_timeout_s 50.0 ms");
  t = a_good_trip(c);
  t.delay_s = 0.01;
  fails_with(t, "earlier than [lcm] rig_timeout_s");
  t = a_good_trip(c);
  t.trip.session_id = 0;  // a rig that offers at once, naming nobody
  fails_with(t, "names no session");
  t = a_good_trip(c);
  t.trip.command_seq = 3;
  fails_with(t, "carries command_seq 3, the last command sent was 500");
  t = a_good_trip(c);
  t.trip.fault_bits = io_state_t::FAULT_NO_SESSION;
  fails_with(t, "no FAULT_COMMAND_TIMEOUT");
  t = a_good_trip(c);
  t.after = t.before;
  fails_with(t, "did not vent");
  t = a_good_trip(c);
  t.served_again = false;
  fails_with(t, "did not serve this engine again");
  t = a_good_trip(c);
  t.engine_fault = FaultCode::kSensorStale;
  fails_with(t, "the engine named it sensor-stale, not rig-timeout");
  t = a_good_trip(c);
  t.not_provoked = "the engine is FAULT";
  fails_with(t, "could not be provoked: the engine is FAULT");
}

/// The engine on the real-time loop driving the rig server over memq:// (one I/O thread for both).
/// Loaded-machine settings: a build beside the suite stalls threads past 50 ms; the timeout and its
/// tolerance are wide so that the check judges the rig, not the machine's load.
struct MemqRig {
  explicit MemqRig(bool timeout_enforced)
      : arm(config().plant, 3),
        rig(arm, parameters(timeout_enforced), 77),
        core(device, c.controller, c.timing, c.safety),
        loop(core, device, 1.0) {
    io.start(RealtimeMode::kTry, 70);
    loop.start(RealtimeMode::kTry);
  }
  ~MemqRig() {
    loop.stop();
    io.stop();
  }
  static Configuration config() {
    Configuration c;
    c.safety.stale_ticks = 40;
    c.safety.missed_deadline_streak = 1000;
    c.lcm.rig_timeout_s = 0.4;
    c.rig_check.timeout_tolerance_s = 0.3;
    c.rig_check.vent_s = 0.5;
    return c;
  }
  RigServerParameters parameters(bool timeout_enforced) {
    RigServerParameters p = testing::RigBench::parameters(c, LcmKey{}, log);
    p.command_timeout_enforced = timeout_enforced;
    return p;
  }
  Configuration c = config();
  std::vector<std::string> log;
  SimulatedArm arm;
  RigServer rig;
  LcmDevice device{LcmDevice::random_session_id(), LcmKey{}, 0.4};
  LcmIoThread io{"memq://", {&device, &rig}};
  EngineCore core;
  RealtimeLoop loop;
};

TEST(RigCheckLimitsMemq, TheRigServerAnnouncesItsLimitsAndItsTimeoutProvokedPasses) {
  MemqRig m(true);
  ASSERT_TRUE(testing::eventually([&] { return m.device.connected(); }, 10.0)) << "the rig never answered";
  RigAnnouncedLimits announced;
  ASSERT_TRUE(testing::eventually([&] { return m.device.read_announced_limits(announced); }, 5.0))
      << "no limits announced";
  EXPECT_EQ(announced.rig_id, 77);
  EXPECT_DOUBLE_EQ(announced.pressure_ceiling_bar, 1.75);
  EXPECT_DOUBLE_EQ(announced.command_timeout_s, 0.4);
  for (const LimitVerdict& v : judge_announced_limits(&announced, m.c, 1)) EXPECT_TRUE(v.pass()) << v.problem;

  const TimeoutObservation t = provoke_command_timeout(m.loop, m.device, m.c, 0.0, nullptr);
  ASSERT_TRUE(t.not_provoked.empty()) << t.not_provoked;
  ASSERT_TRUE(t.tripped);
  const auto chambers = [](const SensorReading& r) {
    return std::to_string(r.joint[0].chamber_bar[0]) + "/" + std::to_string(r.joint[0].chamber_bar[1]) + " bar";
  };
  SCOPED_TRACE("delay " + std::to_string(t.delay_s) + " s, bits " + std::to_string(t.trip.fault_bits) + ", before " +
               chambers(t.before) + ", after " + chambers(t.after) + ", engine: " + fault_name(t.engine_fault) + ": " +
               t.engine_detail);
  EXPECT_EQ(t.trip.session_id, m.device.session_id());
  EXPECT_EQ(t.trip.command_seq, t.last_command_seq);
  EXPECT_NE(t.trip.fault_bits & io_state_t::FAULT_COMMAND_TIMEOUT, 0);
  EXPECT_GT(t.before.joint[0].chamber_bar[0], m.c.controller.gas.ambient_bar + m.c.rig_check.min_change_bar)
      << "the fill held air";
  // Silent only once every valve was closed: the chambers kept their air until the rig vented them.
  EXPECT_LT(t.trip.reading.joint[0].chamber_bar[0], t.before.joint[0].chamber_bar[0] + 0.02) << "filled while silent";
  EXPECT_LT(t.after.joint[0].chamber_bar[0], t.before.joint[0].chamber_bar[0]) << "vented";
  EXPECT_EQ(t.engine_fault, FaultCode::kRigTimeout) << t.engine_detail;
  EXPECT_NE(t.engine_detail.find("vented, as provoked: this host held its commands back for"), std::string::npos)
      << t.engine_detail;
  EXPECT_TRUE(t.served_again);
  const LimitVerdict v = judge_command_timeout(t, m.c);
  EXPECT_TRUE(v.pass()) << v.problem;
  EXPECT_EQ(m.core.state(), EngineState::kSafe) << "the check leaves the engine vented, its provoked fault reset";
}

TEST(RigCheckLimitsMemq, ARigThatNeverTimesOutFailsTheProvokedTimeout) {
  MemqRig m(false);  // io-sim --no-command-timeout
  ASSERT_TRUE(testing::eventually([&] { return m.device.connected(); }, 10.0)) << "the rig never answered";
  const TimeoutObservation t = provoke_command_timeout(m.loop, m.device, m.c, 0.0, nullptr);
  ASSERT_TRUE(t.not_provoked.empty()) << t.not_provoked;
  EXPECT_FALSE(t.tripped);
  EXPECT_GE(t.silent_for_s, 3.0 * m.c.lcm.rig_timeout_s);
  const LimitVerdict v = judge_command_timeout(t, m.c);
  EXPECT_NE(v.problem.find("did not vent by itself"), std::string::npos) << v.problem;
  EXPECT_TRUE(t.served_again) << "its session was never dropped: the engine's commands resume it";
  EXPECT_FALSE(valves_live(m.core.state()));
}

}  // namespace
}  // namespace bellows
