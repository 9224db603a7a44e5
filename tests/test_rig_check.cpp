// The valve test of the first day (engine/operator/valve_test): through the engine on the simulated arm,
// healthy and with injected faults (swapped chamber wiring, a dead inlet, no supply), and
// `bellows rig check`'s exit status and lines.
#include <gtest/gtest.h>

#include <deque>
#include <filesystem>
#include <fstream>
#include <map>
#include <string>

#include "engine/operator/valve_test.hpp"
#include "tests/engine_fixture.hpp"
#include "tests/process_runner.hpp"

#include <nlohmann/json.hpp>

// app/rig_check_command.hpp: kExitRigCheckFailed (the test does not link the app)
constexpr int kRigCheckFailedStatus = 5;

namespace bellows {
namespace {

using testing::EngineFixture;

Configuration with_fault(const std::string& fault) {
  Configuration c;
  c.plant.fault = fault;
  c.plant.fault_at_s = 0.0;
  return c;
}

ValveTestReport check(const Configuration& c) {
  EngineFixture f(c);
  ValveTestReport report =
      run_valve_test(f.clock, c.rig_check, c.safety, c.controller.gas.ambient_bar, c.model.volume_gain_per_rad);
  EXPECT_EQ(f.core.state(), EngineState::kSafe) << "the test ends disarmed (vented)";
  return report;
}

const ValveVerdict& verdict(const ValveTestReport& r, ValveId v) { return r.valves[static_cast<int>(v)]; }

TEST(ValveTest, EveryValveOfAHealthyArmPasses) {
  const ValveTestReport r = check(Configuration{});
  ASSERT_TRUE(r.finished);
  EXPECT_EQ(r.aborted, "");
  for (const ValveVerdict& v : r.valves) {
    EXPECT_TRUE(v.tested) << valve_name(v.valve);
    EXPECT_TRUE(v.pass) << valve_name(v.valve) << ": " << v.problem;
    EXPECT_GT(std::abs(v.own_change_bar), std::abs(v.other_change_bar)) << valve_name(v.valve);
  }
  EXPECT_GT(verdict(r, ValveId::kInletA).own_change_bar, 0.0);
  EXPECT_LT(verdict(r, ValveId::kOutletB).own_change_bar, 0.0);
  EXPECT_TRUE(r.all_pass());
  EXPECT_TRUE(r.failure_lines().empty());
}

TEST(ValveTest, SwappedChamberWiringIsNamedForEveryValve) {
  const ValveTestReport r = check(with_fault("swapped-chambers"));
  ASSERT_TRUE(r.finished);
  EXPECT_EQ(r.aborted, "");
  EXPECT_FALSE(r.all_pass());
  for (const ValveVerdict& v : r.valves) {
    EXPECT_FALSE(v.pass) << valve_name(v.valve);
    EXPECT_NE(v.problem.find("swapped"), std::string::npos) << valve_name(v.valve) << ": " << v.problem;
  }
  EXPECT_EQ(r.failure_lines().size(), 4u);
}

TEST(ValveTest, ADeadInletIsNamedAndTheOthersPass) {
  const ValveTestReport r = check(with_fault("dead-inlet"));
  ASSERT_TRUE(r.finished);
  const ValveVerdict& dead = verdict(r, ValveId::kInletA);
  EXPECT_FALSE(dead.pass);
  EXPECT_NE(dead.problem.find("dead valve"), std::string::npos) << dead.problem;
  EXPECT_EQ(dead.pulses, RigCheckParameters{}.valve_pulse_attempts) << "dead on every pulse";
  EXPECT_TRUE(verdict(r, ValveId::kInletB).pass) << verdict(r, ValveId::kInletB).problem;
  EXPECT_TRUE(verdict(r, ValveId::kOutletB).pass) << verdict(r, ValveId::kOutletB).problem;
  // Outlet A has no air to let out when inlet A is dead: said so, not blamed.
  const ValveVerdict& outlet = verdict(r, ValveId::kOutletA);
  EXPECT_FALSE(outlet.pass);
  EXPECT_NE(outlet.problem.find("see inlet A"), std::string::npos) << outlet.problem;
  // ... and names the fill it had, the other cause when inlet A passed (a fill too short for the link).
  EXPECT_NE(outlet.problem.find("fill_s 0.030 s"), std::string::npos) << outlet.problem;
}

TEST(ValveTest, NoSupplyIsNamedAndNothingIsArmed) {
  EngineFixture f(with_fault("supply-loss"));
  const ValveTestReport r = run_valve_test(f.clock, f.config.rig_check, f.config.safety,
                                           f.config.controller.gas.ambient_bar, f.config.model.volume_gain_per_rad);
  ASSERT_TRUE(r.finished);
  for (const ValveVerdict& v : r.valves) EXPECT_FALSE(v.pass);
  EXPECT_NE(verdict(r, ValveId::kInletA).problem.find("no supply"), std::string::npos);
  EXPECT_NE(verdict(r, ValveId::kOutletB).problem.find("no supply"), std::string::npos);
  for (const EngineEvent& e : f.drain_events()) {
    EXPECT_FALSE(e.kind == EventKind::kStateChanged && e.to == EngineState::kArmed) << "armed without supply";
  }
  EXPECT_EQ(f.core.state(), EngineState::kSafe);
}

TEST(ValveTest, AGuardStillVentsDuringAPulse) {
  // A pulse far too long for the pressure limit: the overpressure guard must end it, not the test.
  Configuration c;
  c.rig_check.valve_pulse_s = 3.0;
  EngineFixture f(c);
  const ValveTestReport r =
      run_valve_test(f.clock, c.rig_check, c.safety, c.controller.gas.ambient_bar, c.model.volume_gain_per_rad);
  ASSERT_TRUE(r.finished);
  EXPECT_NE(r.aborted.find("the engine vented"), std::string::npos) << r.aborted;
  EXPECT_EQ(f.core.state(), EngineState::kFault);
  EXPECT_FALSE(r.all_pass());
  EXPECT_NE(verdict(r, ValveId::kOutletB).problem.find("not tested"), std::string::npos);
}

TEST(ValveTest, TheEmergencyStopEndsTheTest) {
  EngineFixture f;
  std::atomic<bool> stop{true};
  const ValveTestReport r =
      run_valve_test(f.clock, f.config.rig_check, f.config.safety, f.config.controller.gas.ambient_bar,
                     f.config.model.volume_gain_per_rad, &stop);
  EXPECT_NE(r.aborted.find("emergency stop"), std::string::npos) << r.aborted;
  EXPECT_EQ(f.core.state(), EngineState::kFault);
}

TEST(ValveTest, JudgeNamesAValveThatMovesItsChamberTheWrongWay) {
  RigCheckParameters check;
  SensorReading before, after;
  before.joint[0].chamber_bar = {1.2, 1.2};
  before.supply_bar = after.supply_bar = 3.0;
  after.joint[0].chamber_bar = {1.3, 1.2};  // outlet A raised chamber A
  after.time_s = 0.1;
  const ValveVerdict v = judge_valve(ValveId::kOutletA, before, after, 1.013, check, 2.0, 0.35);
  EXPECT_FALSE(v.pass);
  EXPECT_NE(v.problem.find("inlet and outlet of A are swapped"), std::string::npos) << v.problem;
}

TEST(ValveTest, JudgeTakesNoReadingFromBeforeThePulse) {
  RigCheckParameters check;
  SensorReading before;
  before.joint[0].chamber_bar = {1.013, 1.013};
  before.supply_bar = 3.0;
  before.time_s = 2.0;
  SensorReading after = before;  // the link delivered nothing new: the same reading again
  const ValveVerdict v = judge_valve(ValveId::kInletA, before, after, 1.013, check, 2.0, 0.35);
  EXPECT_FALSE(v.pass);
  EXPECT_NE(v.problem.find("no reading taken after the pulse started"), std::string::npos) << v.problem;
  EXPECT_EQ(v.problem.find("dead valve"), std::string::npos) << "a stale link is not a dead valve: " << v.problem;
}

/// A rig whose readings reach the engine `lag_ticks` ticks after they were taken, like a rig over
/// LCM (its state answers a command a period or two later). Each reading keeps the time it was taken.
class LaggingDevice final : public Device {
 public:
  LaggingDevice(SimulatedArm& arm, int lag_ticks, double tick_s) : arm_(arm), lag_ticks_(lag_ticks) {
    taken_.push_back(arm.read_sensors());
    for (int i = 0; i < lag_ticks; ++i) advance(tick_s);  // a full pipe: every tick brings a new reading
  }
  SensorReading read_sensors() override { return taken_.front(); }
  void write_valves(const ValveCommand& command) override { arm_.write_valves(command); }
  void vent() override { arm_.vent(); }
  void advance(double dt_s) override {
    arm_.advance(dt_s);
    taken_.push_back(arm_.read_sensors());
    if (static_cast<int>(taken_.size()) > lag_ticks_ + 1) taken_.pop_front();
  }
  bool time_follows_ticks() const override { return true; }
  const char* name() const override { return "lagging"; }

 private:
  SimulatedArm& arm_;
  int lag_ticks_;
  std::deque<SensorReading> taken_;
};

/// The valve test through the engine on `device` (a wrapper of a simulated arm), on the simulated clock.
ValveTestReport check_on(Device& device, const Configuration& c, double link_lag_s = 0.0) {
  EngineCore core(device, c.controller, c.timing, c.safety);
  SimulatedClock clock(core, device);
  return run_valve_test(clock, c.rig_check, c.safety, c.controller.gas.ambient_bar, c.model.volume_gain_per_rad,
                        nullptr, link_lag_s);
}

ValveTestReport check_lagging(int lag_ticks, double link_lag_s) {
  const Configuration c;
  SimulatedArm arm(c.plant, 1);
  LaggingDevice device(arm, lag_ticks, c.timing.tick_s);
  return check_on(device, c, link_lag_s);
}

// The default 30 ms pulses on a rig whose readings lag by 4 ticks (20 ms): judged on readings that
// do not yet show the step, valves of a healthy rig fail; waiting out the link's lag after each step,
// every valve passes.
TEST(ValveTest, OnALaggingLinkEachStepIsJudgedOnReadingsThatShowIt) {
  const int lag_ticks = 4;
  const double lag_s = lag_ticks * TimingParameters{}.tick_s;
  const ValveTestReport unaware = check_lagging(lag_ticks, 0.0);
  EXPECT_FALSE(unaware.all_pass()) << "the lag is not what this test is about: it never mattered";
  const ValveTestReport settled = check_lagging(lag_ticks, lag_s);
  ASSERT_TRUE(settled.finished);
  EXPECT_EQ(settled.aborted, "");
  for (const ValveVerdict& v : settled.valves) EXPECT_TRUE(v.pass) << valve_name(v.valve) << ": " << v.problem;
}

/// A rig whose link holds back every command of the first `swallowed` pulses of inlet A alone (a T7
/// answering late, a host that did not run the link's thread): the valve stays shut through them.
class SwallowingDevice final : public Device {
 public:
  SwallowingDevice(SimulatedArm& arm, int swallowed) : arm_(arm), swallowed_(swallowed) {}
  SensorReading read_sensors() override { return arm_.read_sensors(); }
  void write_valves(const ValveCommand& command) override {
    const bool inlet_a_alone = command.joint[0].inlet_duty[0] > 0.0 && command.joint[0].inlet_duty[1] == 0.0;
    if (inlet_a_alone && swallowed_ > 0) {
      in_window_ = true;
      return;  // held back: the valves keep the state before
    }
    if (in_window_) {
      in_window_ = false;
      --swallowed_;
    }
    arm_.write_valves(command);
  }
  void vent() override { arm_.vent(); }
  void advance(double dt_s) override { arm_.advance(dt_s); }
  bool time_follows_ticks() const override { return true; }
  const char* name() const override { return "swallowing"; }

 private:
  SimulatedArm& arm_;
  int swallowed_;
  bool in_window_ = false;
};

ValveTestReport check_swallowing(int swallowed, int attempts) {
  Configuration c;
  c.rig_check.valve_pulse_attempts = attempts;
  SimulatedArm arm(c.plant, 1);
  SwallowingDevice device(arm, swallowed);
  return check_on(device, c);
}

// A pulse the link held back moved nothing, as a dead valve would: pulsed again, the valve passes and
// its line says the pulse before moved nothing; with one pulse allowed it is called dead, as before.
TEST(ValveTest, APulseTheLinkHeldBackIsTriedAgainNotCalledDead) {
  const ValveTestReport once = check_swallowing(1, 1);
  const ValveVerdict& blamed = verdict(once, ValveId::kInletA);
  EXPECT_FALSE(blamed.pass);
  EXPECT_NE(blamed.problem.find("dead valve"), std::string::npos) << blamed.problem;
  EXPECT_EQ(blamed.pulses, 1);
  EXPECT_EQ(repeat_note(blamed), "");

  const ValveTestReport again = check_swallowing(1, 2);
  ASSERT_TRUE(again.finished);
  EXPECT_TRUE(again.all_pass()) << (again.failure_lines().empty() ? "" : again.failure_lines()[0]);
  const ValveVerdict& inlet = verdict(again, ValveId::kInletA);
  EXPECT_EQ(inlet.pulses, 2);
  EXPECT_EQ(repeat_note(inlet), " (pulse 2 of 2: the one before moved nothing)");
  EXPECT_EQ(verdict(again, ValveId::kInletB).pulses, 1);
  EXPECT_EQ(repeat_note(verdict(again, ValveId::kInletB)), "");

  // Held back twice, with three pulses allowed: passes on the third.
  const ValveTestReport third = check_swallowing(2, 3);
  EXPECT_TRUE(verdict(third, ValveId::kInletA).pass) << verdict(third, ValveId::kInletA).problem;
  EXPECT_EQ(repeat_note(verdict(third, ValveId::kInletA)), " (pulse 3 of 3: the ones before moved nothing)");
}

TEST(ValvePulse, TheValvesHoldThePulseForItsTicksThenTheAfterState) {
  EngineFixture f;
  f.clock.step(1);
  f.send(CommandKind::kArm);
  ValvePulse pulse;
  pulse.valves.joint[0].inlet_duty = {1.0, 0.0};
  pulse.ticks = 3;
  pulse.id = 7;
  ASSERT_TRUE(f.core.send(EngineCommand::valve_pulse(pulse)));
  for (int i = 0; i < 3; ++i) {
    f.clock.step(1);
    EXPECT_EQ(f.snapshot().valves.joint[0].inlet_duty[0], 1.0) << "tick " << i;
    EXPECT_EQ(f.snapshot().valves.joint[0].outlet_duty[0], 0.0) << "tick " << i;
  }
  f.clock.step(1);  // the first tick after the pulse reports it, with a reading taken after it
  EXPECT_EQ(f.snapshot().valves.joint[0].inlet_duty[0], 0.0);
  bool done = false;
  for (const EngineEvent& e : f.drain_events()) {
    if (e.kind == EventKind::kValvePulseDone) {
      done = true;
      EXPECT_EQ(e.trial_id, 7u);
      EXPECT_GT(e.reading.joint[0].chamber_bar[0], e.reading.joint[0].chamber_bar[1]) << "inlet A filled chamber A";
    }
  }
  EXPECT_TRUE(done);
  f.clock.step(5);
  EXPECT_EQ(f.snapshot().valves.joint[0].inlet_duty[0], 0.0) << "then every valve closed";
  EXPECT_EQ(f.snapshot().valves.joint[0].outlet_duty[1], 0.0);
  EXPECT_EQ(f.core.state(), EngineState::kArmed);
  f.send(CommandKind::kDisarm);
  f.clock.step(1);
  EXPECT_EQ(f.snapshot().valves.joint[0].outlet_duty[0], 1.0) << "disarmed: vented";
}

TEST(ValveTest, ThePulseCommandNeedsArmedValves) {
  EngineFixture f;
  ASSERT_TRUE(f.core.send(EngineCommand::valve_pulse({ValveCommand{}, ValveCommand{}, 10, 1})));
  f.clock.step(2);
  bool refused = false;
  for (const EngineEvent& e : f.drain_events())
    refused |= e.kind == EventKind::kCommandRefused && e.command == CommandKind::kValvePulse;
  EXPECT_TRUE(refused);
}

}  // namespace
}  // namespace bellows

namespace bellows {
namespace {

using testing::run_process;
using testing::write_file;

struct CheckRun {
  int status;
  std::string out, err;
  std::filesystem::path sessions;  // where the check's session went (--data-dir)
};

CheckRun rig_check(const std::string& args, const std::string& fault = "", const std::string& answer = "") {
  const auto dir = testing::make_temp_dir("bellows-rig-check");
  std::string config_arg;
  if (!fault.empty()) {
    config_arg = " --config '" +
                 write_file(dir, "rig.toml", "[plant]\nfault = \"" + fault + "\"\nfault_at_s = 0.0\n").string() + "'";
  }
  const std::string input = answer.empty() ? "/dev/null" : write_file(dir, "answer", answer + "\n").string();
  const std::filesystem::path sessions = dir / "sessions";
  const std::string save = args.find("--no-save") == std::string::npos ? " --data-dir '" + sessions.string() + "'" : "";
  const auto r =
      run_process(std::string(BELLOWS_BINARY) + " rig check" + config_arg + save + " " + args + " < '" + input + "'");
  return {r.exit_code, r.out, r.err, sessions};
}

int count_of(const std::string& text, const std::string& what) {
  int n = 0;
  for (auto at = text.find(what); at != std::string::npos; at = text.find(what, at + 1)) ++n;
  return n;
}

TEST(RigCheckCli, AHealthyArmPassesWithStatusZero) {
  const CheckRun r = rig_check("--yes");
  EXPECT_EQ(r.status, 0) << r.out << r.err;
  EXPECT_EQ(count_of(r.out, " pass "), 4) << r.out;
  EXPECT_NE(r.out.find("no volts"), std::string::npos) << "the simulated arm says it has no volts: " << r.out;
  EXPECT_NE(r.out.find("supply"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("rig check: every valve passed"), std::string::npos) << r.out;
}

TEST(RigCheckCli, EachDrilledProblemIsNamedWithOneLinePerFailedValve) {
  const CheckRun swapped = rig_check("--yes", "swapped-chambers");
  EXPECT_EQ(swapped.status, kRigCheckFailedStatus) << swapped.out << swapped.err;
  EXPECT_EQ(count_of(swapped.out, "FAIL "), 4) << swapped.out;
  EXPECT_EQ(count_of(swapped.out, "are swapped"), 4) << swapped.out;

  const CheckRun dead = rig_check("--yes", "dead-inlet");
  EXPECT_EQ(dead.status, kRigCheckFailedStatus) << dead.out << dead.err;
  EXPECT_NE(dead.out.find("FAIL inlet A: dead valve"), std::string::npos) << dead.out;
  EXPECT_EQ(dead.out.find("FAIL inlet B"), std::string::npos) << dead.out;

  const CheckRun no_supply = rig_check("--yes", "supply-loss");
  EXPECT_EQ(no_supply.status, kRigCheckFailedStatus) << no_supply.out << no_supply.err;
  EXPECT_NE(no_supply.out.find("FAIL inlet A: no supply"), std::string::npos) << no_supply.out;
  EXPECT_NE(no_supply.out.find("FAIL inlet B: no supply"), std::string::npos) << no_supply.out;
}

TEST(RigCheckCli, NothingOpensWithoutTheOperatorsYes) {
  const CheckRun r = rig_check("", "", "n");
  EXPECT_EQ(r.status, 2) << r.out << r.err;
  EXPECT_NE(r.err.find("not confirmed: no valve was opened"), std::string::npos) << r.err;
  EXPECT_EQ(r.out.find(" pass "), std::string::npos) << r.out;
  EXPECT_EQ(rig_check("", "", "y").status, 0);
}

TEST(RigCheckCli, JsonNamesEveryValve) {
  const CheckRun r = rig_check("--yes --json", "dead-inlet");
  ASSERT_EQ(r.status, kRigCheckFailedStatus) << r.err;
  const auto report = nlohmann::json::parse(r.out);
  EXPECT_EQ(report.at("device"), "sim");
  ASSERT_EQ(report.at("valves").size(), 4u);
  EXPECT_EQ(report.at("valves")[0].at("valve"), "inlet A");
  EXPECT_FALSE(report.at("valves")[0].at("pass").get<bool>());
  EXPECT_TRUE(report.at("valves")[1].at("pass").get<bool>());
  EXPECT_FALSE(report.at("all_pass").get<bool>());
}

// A rig check is recorded in a session like a run: the device, each input, each valve's verdict
// and the outcome are its events (the manifest), and --json names the session.
TEST(RigCheckCli, TheCheckIsRecordedInASession) {
  const CheckRun r = rig_check("--yes --json", "dead-inlet");
  ASSERT_EQ(r.status, kRigCheckFailedStatus) << r.err;
  const auto report = nlohmann::json::parse(r.out);
  ASSERT_TRUE(report.at("session").is_string()) << r.out;
  const std::filesystem::path session = report.at("session").get<std::string>();
  EXPECT_EQ(session.parent_path(), r.sessions);
  std::ifstream in(session / "manifest.json");
  const auto manifest = nlohmann::json::parse(in);
  EXPECT_EQ(manifest.at("device"), "sim");
  std::map<std::string, std::vector<std::string>> events;
  for (const auto& e : manifest.at("events"))
    events[e.at("kind").get<std::string>()].push_back(e.at("message").get<std::string>());
  ASSERT_EQ(events["start"].size(), 1u);
  EXPECT_NE(events["start"][0].find("bellows rig check"), std::string::npos) << events["start"][0];
  ASSERT_EQ(events["rig-input"].size(), 1u);  // the simulated arm: one line of values, no volts
  EXPECT_NE(events["rig-input"][0].find("supply"), std::string::npos);
  ASSERT_EQ(events["valve-test"].size(), 4u);
  EXPECT_EQ(events["valve-test"][0].rfind("inlet A FAIL: dead valve", 0), 0u) << events["valve-test"][0];
  EXPECT_EQ(events["valve-test"][1].rfind("inlet B pass", 0), 0u) << events["valve-test"][1];
  ASSERT_EQ(events["finish"].size(), 1u);
  EXPECT_NE(events["finish"][0].find("valves failed"), std::string::npos) << events["finish"][0];

  const CheckRun unsaved = rig_check("--yes --json --no-save");
  EXPECT_EQ(unsaved.status, 0) << unsaved.err;
  EXPECT_TRUE(nlohmann::json::parse(unsaved.out).at("session").is_null());
  EXPECT_FALSE(std::filesystem::exists(unsaved.sessions));
}

}  // namespace
}  // namespace bellows
