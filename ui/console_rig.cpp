// The Rig screen (the first day at the bench): the device's inputs live, its link's health, and
// the valve test (engine/operator/valve_test) driven through the engine's commands like any trial, and
// zeroing the angle (written into the rig profile by the app's callback).
#include <cmath>
#include <numbers>

#include "ui/canvas.hpp"
#include "ui/console_controller.hpp"
#include "ui/keys.hpp"

namespace bellows::ui {
namespace {

constexpr double kRigRefreshS = 0.25;  // raw inputs and link figures: a few times a second is live enough

}  // namespace

bool ConsoleController::handle_rig_key(int k) {
  if (k == 'z') {
    if (!env_.zero_angle) {
      set_status("zeroing the angle writes the rig profile: it needs --device t7 --rig-profile FILE", true);
    } else if (valves_live(state_.engine_state) || !state_.live_valid) {
      set_status("zeroing the angle: only while SAFE (disarm first), with the arm at rest", true);
    } else {
      open_dialog(DialogKind::kConfirmZeroAngle, "Zero the angle here?",
                  {format("The arm reads %+.3f deg now: this becomes 0 deg.",
                          state_.live.reading.joint[0].angle_rad * 180.0 / std::numbers::pi),
                   "Hold the arm at rest where it should read zero (hanging straight).",
                   "The rig profile's angle_zero_rad is written to its file."},
                  "y zero it   n cancel");
    }
    return true;
  }
  if (k != 'v') return false;
  if (valve_test_ && valve_test_->running()) {
    set_status("the valve test is running (Space stops it)", true);
  } else if (state_.run.mode != RunProgress::Mode::kIdle || in_flight_ ||
             state_.engine_state == EngineState::kRunning) {
    set_status("valve test: not while trials run (x stops them)", true);
  } else if (state_.engine_state == EngineState::kFault) {
    set_status("valve test: a fault is latched: reset it (R) first", true);
  } else {
    const RigCheckParameters& c = env_.config.rig_check;
    open_dialog(DialogKind::kConfirmValveTest, "Valve test: open each valve alone?",
                {format("Inlet A, inlet B, outlet A, outlet B in turn, each fully open for %.3f s", c.valve_pulse_s),
                 format("(vented %.1f s before each; air let in for %.3f s before an outlet).", c.vent_s, c.fill_s),
                 "The valves are armed for it and the arm WILL move. Clear it first.",
                 "The guards stay on; Space vents at once."},
                "y start   n cancel");
  }
  return true;
}

void ConsoleController::zero_angle() {
  try {
    const std::string done = env_.zero_angle(state_.live.reading.joint[0].angle_rad);
    log(LogSource::kOperator, "angle zeroed: " + done);  // the session's event log keeps it
    set_status("angle zeroed: " + done, false);
  } catch (const std::exception& e) {
    log(LogSource::kOperator, std::string("angle not zeroed: ") + e.what(), true);
    set_status(std::string("angle not zeroed: ") + e.what(), true);
  }
}

void ConsoleController::start_valve_test() {
  valve_test_ = std::make_unique<ValveTest>(
      env_.config.rig_check, env_.config.safety, env_.config.controller.gas.ambient_bar, env_.config.timing.tick_s,
      env_.config.model.volume_gain_per_rad, env_.device_health ? link_lag_s(env_.device_health()) : 0.0);
  const SensorReading latest = state_.live_valid ? state_.live.reading : SensorReading{};
  state_.rig.verdicts_logged = false;
  if (!send_valve_test_commands(valve_test_->begin(state_.engine_state, latest))) return;
  log(LogSource::kOperator, format("valve test started (%.3f s per valve)", env_.config.rig_check.valve_pulse_s));
  show_valve_verdicts();
}

void ConsoleController::forward_to_valve_test(const EngineEvent& event) {
  if (!valve_test_ || !valve_test_->running()) return;
  if (!send_valve_test_commands(valve_test_->on_event(event))) return;
  show_valve_verdicts();
}

bool ConsoleController::send_valve_test_commands(const std::vector<EngineCommand>& commands) {
  for (const EngineCommand& c : commands) {
    if (send(c, "valve test")) continue;
    // The test would wait for ever for a pulse the engine never took: stop it, valves vented.
    valve_test_->abandon("the engine refused a valve test command");
    emergency_stop("valve test command refused");
    show_valve_verdicts();
    return false;
  }
  return true;
}

void ConsoleController::show_valve_verdicts() {
  if (!valve_test_) return;
  const ValveTestReport& r = valve_test_->report();
  RigView& rig = state_.rig;
  rig.test_running = valve_test_->running();
  rig.test_progress = valve_test_->progress();
  rig.valves.clear();
  for (const ValveVerdict& v : r.valves) {
    RigView::ValveLine line{valve_name(v.valve), v.tested, v.pass, {}};
    if (v.pass) {
      line.text =
          format("own chamber %+.3f bar, other %+.3f bar", v.own_change_bar, v.other_change_bar) + repeat_note(v);
    } else if (v.tested || !v.problem.empty()) {
      line.text = v.problem + repeat_note(v);
    } else {
      line.text = "waiting";
    }
    rig.valves.push_back(std::move(line));
  }
  set_status("valve test: " + rig.test_progress, false);
  if (r.finished && !rig.verdicts_logged) {
    // Finished: every verdict into the log, so the session keeps it.
    rig.verdicts_logged = true;
    int failed = 0;
    for (const RigView::ValveLine& line : rig.valves) {
      failed += line.pass ? 0 : 1;
      log(LogSource::kOperator,
          "valve test: " + line.valve + (line.pass ? " pass (" : " FAIL: ") + line.text + (line.pass ? ")" : ""),
          !line.pass);
    }
    set_status(failed == 0 ? "valve test: every valve passed"
                           : format("valve test: %d of %d valves failed (see the Rig screen)", failed, kValveCount),
               failed != 0);
  }
}

void ConsoleController::refresh_rig(double now_s) {
  if (last_rig_refresh_s_ >= 0.0 && now_s - last_rig_refresh_s_ < kRigRefreshS) return;
  last_rig_refresh_s_ = now_s;
  if (env_.device_health) link_ = env_.device_health();
  state_.rig.where = env_.device_where;
  state_.rig.rig_profile = env_.rig_profile;
  if (state_.screen == Screen::kRig && env_.raw_inputs) {
    state_.rig.raw = env_.raw_inputs();
    ++revision_;
  }
}

void ConsoleController::add_link_health(DeviceHealth& health) {
  const bellows::DeviceHealth& l = link_;
  if (!l.has_link) return;
  if (!l.connected) {
    health.ok = false;
    health.status = l.exchanges == 0 ? "no link yet" : "link lost";
  }
  health.status +=
      format(", rt p99 %.1f ms, %llu err, %llu stale", l.round_trip_p99_ms,
             static_cast<unsigned long long>(l.link_errors), static_cast<unsigned long long>(l.stale_readings));
}

}  // namespace bellows::ui
