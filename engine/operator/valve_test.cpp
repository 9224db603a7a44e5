#include "engine/operator/valve_test.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace bellows {
namespace {

int chamber_of(ValveId valve) { return valve == ValveId::kInletA || valve == ValveId::kOutletA ? 0 : 1; }
bool is_inlet(ValveId valve) { return valve == ValveId::kInletA || valve == ValveId::kInletB; }
const char* chamber_name(int chamber) { return chamber == 0 ? "A" : "B"; }

template <typename... Args>
std::string format(const char* pattern, Args... args) {
  char text[320];
  std::snprintf(text, sizeof text, pattern, args...);
  return text;
}

}  // namespace

const char* valve_name(ValveId valve) {
  switch (valve) {
    case ValveId::kInletA:
      return "inlet A";
    case ValveId::kInletB:
      return "inlet B";
    case ValveId::kOutletA:
      return "outlet A";
    case ValveId::kOutletB:
      return "outlet B";
  }
  return "?";
}

bool ValveTestReport::all_pass() const {
  return finished && aborted.empty() &&
         std::all_of(valves.begin(), valves.end(), [](const ValveVerdict& v) { return v.pass; });
}

std::vector<std::string> ValveTestReport::failure_lines() const {
  std::vector<std::string> lines;
  for (const ValveVerdict& v : valves) {
    if (!v.pass) lines.push_back(std::string(valve_name(v.valve)) + ": " + v.problem);
  }
  return lines;
}

// The air in a chamber, as the pressure it would have at the nominal volume: p (1 +- beta alpha).
// A closed chamber that the turning arm squeezes keeps its air; its pressure alone would not.
double air_bar(const SensorReading& r, int chamber, double volume_gain_per_rad) {
  const double sign = chamber == 0 ? 1.0 : -1.0;
  return r.joint[0].chamber_bar[chamber] * (1.0 + sign * volume_gain_per_rad * r.joint[0].angle_rad);
}

ValveVerdict judge_valve(ValveId valve, const SensorReading& before, const SensorReading& after, double ambient_bar,
                         const RigCheckParameters& check, double supply_min_bar, double volume_gain_per_rad) {
  const int own = chamber_of(valve), other = 1 - own;
  const double sign = is_inlet(valve) ? 1.0 : -1.0;  // an inlet raises its chamber, an outlet lowers it
  const char* way = is_inlet(valve) ? "rise" : "fall";
  const double m = check.min_change_bar;
  ValveVerdict v;
  v.valve = valve;
  v.tested = true;
  v.own_change_bar = air_bar(after, own, volume_gain_per_rad) - air_bar(before, own, volume_gain_per_rad);
  v.other_change_bar = air_bar(after, other, volume_gain_per_rad) - air_bar(before, other, volume_gain_per_rad);
  const double own_move = sign * v.own_change_bar, other_move = sign * v.other_change_bar;
  if (!(after.time_s > before.time_s)) {  // the same reading twice: nothing to judge the pulse by
    v.moved_nothing = true;
    v.problem = format(
        "not judged: no reading taken after the pulse started (the newest is from %.3f s): the link to "
        "the rig delivers no fresh readings",
        after.time_s);
  } else if (!std::isfinite(own_move) || !std::isfinite(other_move)) {
    v.problem = "a chamber pressure reads not-a-number: check the pressure sensors' inputs";
  } else if (!is_inlet(valve) && before.joint[0].chamber_bar[own] - ambient_bar < m) {
    // Either inlet's own test failed, or the fill was too short for this link (a late tick eats it).
    v.moved_nothing = true;
    v.problem = format(
        "not tested: chamber %s held no air to let out (%.3f bar after [rig_check] fill_s %.3f s of both "
        "inlets; see inlet %s: if it passed, a longer fill_s)",
        chamber_name(own), before.joint[0].chamber_bar[own], check.fill_s, chamber_name(own));
  } else if (own_move >= m && own_move >= other_move + m) {
    v.pass = true;
  } else if (other_move >= m && other_move >= own_move + m) {
    v.problem = format(
        "chamber %s moved (%+.3f bar), not %s (%+.3f bar): the tubes, valve lines or pressure inputs of "
        "A and B are swapped",
        chamber_name(other), v.other_change_bar, chamber_name(own), v.own_change_bar);
  } else if (own_move <= -m) {
    v.problem = format("chamber %s went the wrong way (%+.3f bar): the inlet and outlet of %s are swapped",
                       chamber_name(own), v.own_change_bar, chamber_name(own));
  } else if (own_move >= m) {
    v.problem = format("both chambers moved alike (%+.3f and %+.3f bar): a leak between them or a shared line",
                       v.own_change_bar, v.other_change_bar);
  } else if (is_inlet(valve) && std::min(before.supply_bar, after.supply_bar) < supply_min_bar) {
    v.problem = format("no supply: the supply reads %.2f bar (below [safety] supply_min_bar %.2f)",
                       std::min(before.supply_bar, after.supply_bar), supply_min_bar);
  } else {
    v.moved_nothing = true;
    v.problem = format(
        "dead valve: chamber %s did not %s (%+.3f bar in [rig_check] valve_pulse_s %.3f s): check the "
        "valve's line, its power and the valve%s",
        chamber_name(own), way, v.own_change_bar, check.valve_pulse_s,
        is_inlet(valve) ? ", and that air reaches it" : "");
  }
  return v;
}

std::string repeat_note(const ValveVerdict& verdict) {
  if (verdict.pulses <= 1) return "";
  return format(" (pulse %d of %d: the one%s before moved nothing)", verdict.pulses, verdict.pulses,
                verdict.pulses > 2 ? "s" : "");
}

ValveTest::ValveTest(const RigCheckParameters& check, const SafetyParameters& safety, double ambient_bar, double tick_s,
                     double volume_gain_per_rad, double link_lag_s)
    : check_(check),
      safety_(safety),
      ambient_bar_(ambient_bar),
      tick_s_(tick_s),
      volume_gain_per_rad_(volume_gain_per_rad),
      settle_ticks_(link_lag_s > 0.0 ? static_cast<int>(std::ceil(link_lag_s / tick_s)) : 0) {
  for (int i = 0; i < kValveCount; ++i) report_.valves[i].valve = static_cast<ValveId>(i);
}

std::vector<EngineCommand> ValveTest::begin(EngineState state, const SensorReading& latest) {
  started_ = true;
  if (state != EngineState::kSafe && state != EngineState::kArmed) {
    finish_with(state == EngineState::kRunning ? "a trial is running" : "a fault is latched: reset it first");
    return {};
  }
  if (!(latest.supply_bar >= safety_.supply_min_bar)) {  // arming would fault (supply-low) at once
    for (ValveVerdict& v : report_.valves) {
      v.problem = is_inlet(v.valve)
                      ? format("no supply: the supply reads %.2f bar (below [safety] supply_min_bar %.2f)",
                               latest.supply_bar, safety_.supply_min_bar)
                      : std::string("not tested: no supply to fill the chambers");
    }
    report_.finished = true;
    return {};
  }
  std::vector<EngineCommand> commands;
  if (state == EngineState::kSafe) commands.push_back(EngineCommand::of(CommandKind::kArm));
  valve_ = 0;
  step_ = Step::kVent;
  commands.push_back(command_for(step_));
  return commands;
}

EngineCommand ValveTest::command_for(Step step) {
  const auto ticks_of = [this](double seconds) {
    return std::max(1, static_cast<int>(std::lround(seconds / tick_s_)));
  };
  ValvePulse pulse;  // `after`: every valve closed, the chambers keep what the pulse left
  pulse.id = ++pulse_id_;
  pulse.settle_ticks = settle_ticks_;  // so that the reading shows all the step did
  switch (step) {
    case Step::kVent:
      pulse.valves = ValveCommand::vented();
      pulse.ticks = ticks_of(check_.vent_s);
      break;
    case Step::kFill:
      pulse.valves.joint[0].inlet_duty = {1.0, 1.0};
      pulse.ticks = ticks_of(check_.fill_s);
      break;
    case Step::kPulse: {
      const auto valve = static_cast<ValveId>(valve_);
      auto& duties = is_inlet(valve) ? pulse.valves.joint[0].inlet_duty : pulse.valves.joint[0].outlet_duty;
      duties[chamber_of(valve)] = 1.0;
      pulse.ticks = ticks_of(check_.valve_pulse_s);
      break;
    }
  }
  return EngineCommand::valve_pulse(pulse);
}

std::vector<EngineCommand> ValveTest::next_step() {
  const bool outlet = !is_inlet(static_cast<ValveId>(valve_));
  if (step_ == Step::kVent) {
    step_ = outlet ? Step::kFill : Step::kPulse;
  } else if (step_ == Step::kFill) {
    step_ = Step::kPulse;
  } else {
    attempt_ = 0;
    if (++valve_ == kValveCount) {
      report_.finished = true;
      return {EngineCommand::of(CommandKind::kDisarm)};  // vents
    }
    step_ = Step::kVent;
  }
  return {command_for(step_)};
}

std::vector<EngineCommand> ValveTest::on_event(const EngineEvent& event) {
  if (!running()) return {};
  switch (event.kind) {
    case EventKind::kValvePulseDone:
      if (event.trial_id != pulse_id_) return {};
      if (step_ == Step::kPulse) {
        const auto valve = static_cast<ValveId>(valve_);
        ValveVerdict verdict = judge_valve(valve, before_, event.reading, ambient_bar_, check_, safety_.supply_min_bar,
                                           volume_gain_per_rad_);
        verdict.pulses = ++attempt_;
        if (verdict.moved_nothing && attempt_ < check_.valve_pulse_attempts) {
          step_ = Step::kVent;  // the same valve again, from ambient as the first time
          return {command_for(step_)};
        }
        report_.valves[valve_] = verdict;
      } else {
        before_ = event.reading;
      }
      return next_step();
    case EventKind::kFault:
      finish_with(std::string("the engine vented: ") + fault_name(event.fault) + ": " + fault_message(event.fault));
      return {};
    case EventKind::kCommandRefused:
      if (event.command != CommandKind::kValvePulse && event.command != CommandKind::kArm) return {};
      finish_with(std::string("the engine refused ") + to_string(event.command) + ": " + event.refusal);
      return {EngineCommand::of(CommandKind::kDisarm)};
    case EventKind::kStateChanged:
      if (event.to == EngineState::kSafe) finish_with("disarmed during the test");
      if (event.to == EngineState::kRunning) {  // a trial ends the operator's valves
        finish_with("a trial started during the test");
        return {EngineCommand::of(CommandKind::kAbortTrial), EngineCommand::of(CommandKind::kDisarm)};
      }
      return {};
    default:
      return {};
  }
}

void ValveTest::abandon(const std::string& why) {
  if (running()) finish_with(why);
}

void ValveTest::finish_with(const std::string& why) {
  report_.aborted = why;
  report_.finished = true;
  for (int i = valve_; i < kValveCount; ++i) {
    if (!report_.valves[i].tested) report_.valves[i].problem = "not tested: " + why;
  }
}

std::string ValveTest::progress() const {
  if (!started_) return "not started";
  if (report_.finished) return report_.aborted.empty() ? "done" : "stopped: " + report_.aborted;
  const char* what = step_ == Step::kVent   ? "venting both chambers"
                     : step_ == Step::kFill ? "filling both chambers"
                                            : "pulsing";
  return format("%s: %s%s (%d of %d)", valve_name(static_cast<ValveId>(valve_)), what,
                attempt_ > 0 ? " again: the pulse before moved nothing" : "", valve_ + 1, kValveCount);
}

ValveTestReport run_valve_test(EngineDriver& driver, const RigCheckParameters& check, const SafetyParameters& safety,
                               double ambient_bar, double volume_gain_per_rad, const std::atomic<bool>* stop,
                               double link_lag_s) {
  EngineCore& core = driver.core();
  ValveTest test(check, safety, ambient_bar, core.timing().tick_s, volume_gain_per_rad, link_lag_s);
  TickRecord latest;
  driver.await();  // at least one tick: a reading to check the supply with
  while (!core.read_snapshot(latest)) driver.await();
  EngineEvent event;
  while (core.poll_event(event)) {
  }  // what happened before the test is not its business
  // A command the engine's queue refused would leave the test waiting for ever: stop instead.
  bool refused = false;
  bool stopped = false;
  const auto send_all = [&](const std::vector<EngineCommand>& commands) {
    for (const EngineCommand& c : commands) refused = refused || !core.send(c);
  };
  send_all(test.begin(core.state(), latest.reading));
  while (test.running()) {
    if (refused) {
      core.request_emergency_stop();
      test.abandon("the engine's command queue refused a command (emergency stop)");
      stopped = true;
      break;
    }
    if (stop != nullptr && stop->load(std::memory_order_relaxed)) {
      core.request_emergency_stop();
      test.abandon("stopped by the operator (emergency stop)");
      stopped = true;
      break;
    }
    driver.await();
    while (core.poll_event(event)) send_all(test.on_event(event));
  }
  // Until the final disarm (or stop) has taken effect: the valves are vented when this returns.
  // After a stop, until the engine has acted on the latch (FAULT, vented).
  if (stopped) {
    while (core.state() != EngineState::kFault) driver.await();
  }
  while (valves_live(core.state())) driver.await();
  return test.report();
}

}  // namespace bellows
