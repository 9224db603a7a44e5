#include "app/rig_check_limits.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "devices/lcm_channels.hpp"
#include "devices/lcm_io_thread.hpp"
#include "engine/base/units.hpp"
#include "engine/rt/engine_core.hpp"
#include "engine/rt/engine_state.hpp"

namespace bellows {
namespace {

template <typename... Args>
std::string text(const char* pattern, Args... args) {
  char line[480];
  std::snprintf(line, sizeof line, pattern, args...);
  return line;
}

// How closely an announced value must match the configuration's: a rig configured from the same
// numbers announces them to within rounding.
constexpr double kPeriodTolerance = 0.01;  // relative
constexpr double kTimeoutTolerance_s = 0.0005;
constexpr double kPressureTolerance_bar = 0.005;
constexpr double kAngleTolerance_deg = 0.05;

double excess_bar(const SensorReading& r, double ambient_bar) {
  return std::max(r.joint[0].chamber_bar[0], r.joint[0].chamber_bar[1]) - ambient_bar;
}

}  // namespace

std::vector<LimitVerdict> judge_announced_limits(const RigAnnouncedLimits* announced, const Configuration& config,
                                                 int joints) {
  if (announced == nullptr) {
    return {
        {"announced limits", "none", "an io_rig_limits_t on BELLOWS_IO_LIMITS once a second",
         text("the rig announced no limits (io_rig_limits_t on BELLOWS_IO_LIMITS) in %.1f s: its ceiling, range and "
              "timeout cannot be compared with this configuration (docs/lcm-protocol.md, \"Write your own rig\")",
              2.0 * kIoLimitsPeriod_s + 0.5)}};
  }
  const RigAnnouncedLimits& a = *announced;
  std::vector<LimitVerdict> out;

  LimitVerdict arm{"joints", text("%d", a.joints), text("%d, the arm of this configuration", joints), ""};
  if (a.joints != joints)
    arm.problem = text("the rig serves an arm of %d joints, this configuration's has %d", a.joints, joints);
  out.push_back(arm);

  const double tick_s = config.timing.tick_s;
  LimitVerdict period{"state period", text("%.2f ms", a.period_s * 1e3), text("[timing] tick_s %.2f ms", tick_s * 1e3),
                      ""};
  if (std::abs(a.period_s - tick_s) > kPeriodTolerance * tick_s) {
    period.problem = text(
        "the rig publishes a state every %.2f ms, the engine ticks every %.2f ms ([timing] tick_s): give "
        "both the same",
        a.period_s * 1e3, tick_s * 1e3);
  }
  out.push_back(period);

  const double timeout_s = config.lcm.rig_timeout_s;
  LimitVerdict timeout{"command timeout", text("%.1f ms", a.command_timeout_s * 1e3),
                       text("[lcm] rig_timeout_s %.1f ms", timeout_s * 1e3), ""};
  if (std::abs(a.command_timeout_s - timeout_s) > kTimeoutTolerance_s) {
    timeout.problem = text(
        "the rig vents after %.1f ms without commands, this configuration expects %.1f ms ([lcm] "
        "rig_timeout_s): %s",
        a.command_timeout_s * 1e3, timeout_s * 1e3,
        a.command_timeout_s > timeout_s ? "a stalled engine leaves the arm driven longer than planned"
                                        : "the rig drops sessions on delays the engine rides through");
  }
  out.push_back(timeout);

  const double p_max = config.controller.p_max_bar;
  const double ceiling = p_max + config.lcm.rig_pressure_margin_bar;
  const double pressure_guard = p_max + config.safety.pressure_margin_bar;
  LimitVerdict pressure{
      "pressure ceiling", text("%.3f bar", a.pressure_ceiling_bar),
      text("%.3f bar = [controller] p_max_bar %.3f + [lcm] rig_pressure_margin_bar %.3f; the engine's guard "
           "%.3f bar",
           ceiling, p_max, config.lcm.rig_pressure_margin_bar, pressure_guard),
      ""};
  if (std::abs(a.pressure_ceiling_bar - ceiling) > kPressureTolerance_bar) {
    pressure.problem = text(
        "the rig vents chambers above %.3f bar absolute, this configuration expects %.3f bar (p_max %.3f "
        "+ margin %.3f)%s: give the rig the engine's [controller] p_max_bar and [lcm] "
        "rig_pressure_margin_bar",
        a.pressure_ceiling_bar, ceiling, p_max, config.lcm.rig_pressure_margin_bar,
        a.pressure_ceiling_bar <= pressure_guard
            ? text("; at or below the engine's own guard %.3f bar, so the rig would cut the engine's "
                   "set points short and trip before the engine faults",
                   pressure_guard)
                  .c_str()
            : "");
  }
  out.push_back(pressure);

  const double range_deg = config.lcm.rig_angle_limit_deg;
  const double guard_deg = config.safety.angle_limit_deg_of(0);
  const double announced_deg = a.angle_limit_rad * kDegPerRad;
  LimitVerdict range{"angle range", text("%.1f deg", announced_deg),
                     text("[lcm] rig_angle_limit_deg %.1f deg; the engine's guard %.1f deg", range_deg, guard_deg), ""};
  if (std::abs(announced_deg - range_deg) > kAngleTolerance_deg) {
    range.problem =
        text("the rig's angle range is %.1f deg, this configuration expects %.1f deg ([lcm] rig_angle_limit_deg)%s",
             announced_deg, range_deg,
             announced_deg < guard_deg
                 ? text(" and it is inside the engine's guard %.1f deg ([safety] angle_limit_deg): a runaway "
                        "would be stopped by the rig (rig-limit), not by the engine; set the guard below the "
                        "rig's range, or the rig's range beyond the guard",
                        guard_deg)
                       .c_str()
                 : ": set [lcm] rig_angle_limit_deg to the rig's");
  }
  out.push_back(range);
  return out;
}

TimeoutObservation provoke_command_timeout(EngineDriver& driver, LcmDevice& device, const Configuration& config,
                                           double link_lag_s, const std::atomic<bool>* stop) {
  EngineCore& core = driver.core();
  TimeoutObservation seen;
  seen.session_id = device.session_id();
  const double tick_s = config.timing.tick_s;
  const auto stopped = [&] { return stop != nullptr && stop->load(std::memory_order_relaxed); };
  const auto ticks_of = [&](double s) { return std::max(1, static_cast<int>(std::lround(s / tick_s))); };
  // Waits (ticking) until `done` or `limit_s` of the monotonic clock have passed.
  const auto wait_until = [&](const auto& done, double limit_s) {
    const double until_s = monotonic_s() + limit_s;
    while (!done()) {
      if (stopped() || monotonic_s() > until_s) return false;
      driver.await();
    }
    return true;
  };
  EngineEvent event;
  while (core.poll_event(event)) {
  }
  const EngineState state = core.state();
  if (state != EngineState::kSafe && state != EngineState::kArmed) {
    seen.not_provoked = std::string("the engine is ") + to_string(state);
    return seen;
  }
  // Armed, a little air in both chambers (they stay near each other: the arm barely turns), every valve closed.
  if (state == EngineState::kSafe && !core.send(EngineCommand::of(CommandKind::kArm))) {
    seen.not_provoked = "the engine's command queue refused to arm";
    return seen;
  }
  ValvePulse fill;
  fill.valves.joint[0].inlet_duty = {1.0, 1.0};
  fill.ticks = ticks_of(config.rig_check.fill_s);
  fill.settle_ticks = static_cast<int>(std::ceil(link_lag_s / tick_s));
  fill.id = 0x7105;
  bool filled = false;
  if (!core.send(EngineCommand::valve_pulse(fill))) {
    seen.not_provoked = "the engine's command queue refused the fill";
    return seen;
  }
  const double setup_limit_s = config.lcm.connect_timeout_s + config.rig_check.fill_s;
  wait_until(
      [&] {
        while (core.poll_event(event)) {
          if (event.kind == EventKind::kValvePulseDone && event.trial_id == fill.id) {
            filled = true;
            seen.before = event.reading;
          }
          if (event.kind == EventKind::kFault)
            seen.not_provoked = std::string("the engine vented: ") + fault_name(event.fault);
          if (event.kind == EventKind::kCommandRefused)
            seen.not_provoked = std::string("the engine refused: ") + event.refusal;
        }
        return filled || !seen.not_provoked.empty();
      },
      setup_limit_s);
  if (!filled || !seen.not_provoked.empty()) {
    if (seen.not_provoked.empty())
      seen.not_provoked = stopped() ? "stopped by the operator" : "the fill did not finish";
    (void)core.send(EngineCommand::of(CommandKind::kDisarm));
    return seen;
  }

  // Silence only once the rig applies a command with every valve closed (one sent a tick after the
  // fill ended): never with the fill's open inlets as the last word, which would fill the chambers
  // to the rig's ceiling while the engine cannot be heard.
  driver.await();
  driver.await();
  const std::int64_t closed_seq = device.last_command_seq();
  RigStateSeen applied;
  if (!wait_until([&] { return device.read_rig_state(applied) && applied.command_seq >= closed_seq; },
                  config.lcm.connect_timeout_s)) {
    seen.not_provoked = "the rig did not apply the command that closes every valve";
    (void)core.send(EngineCommand::of(CommandKind::kDisarm));
    return seen;
  }
  // The air held is what the rig reports with every valve closed: the fill's last reading came before
  // its last open-inlet periods were applied, and the chambers rose a little after it.
  seen.before = applied.reading;
  // Silence: the rig hears nothing, as from an engine that stalled.
  device.hold_commands(true);
  const bool held = wait_until([&] { return device.commands_held(); }, 1.0);
  seen.last_command_seq = device.last_command_seq();
  const double last_sent_s = device.last_command_sent_s();
  const double timeout_s = config.lcm.rig_timeout_s;
  const double window_s = 3.0 * timeout_s + config.rig_check.timeout_tolerance_s;
  RigStateSeen trip;
  // The engine's vent cannot be heard while it is silent: should it fault for a reason of its own
  // before the rig trips, it speaks again at once.
  bool engine_faulted = false;
  seen.tripped = held &&
                 wait_until(
                     [&] {
                       if (device.read_trip_seen(trip) && trip.received_s > last_sent_s) return true;
                       engine_faulted = core.state() == EngineState::kFault;
                       return engine_faulted;
                     },
                     last_sent_s + window_s - monotonic_s()) &&
                 !engine_faulted;
  if (engine_faulted) {
    device.hold_commands(false);
    seen.not_provoked =
        std::string("the engine faulted while silent, before the rig tripped: ") + fault_name(core.fault());
    return seen;
  }
  seen.silent_for_s = monotonic_s() - last_sent_s;
  if (seen.tripped) {
    seen.trip = trip;
    seen.delay_s = trip.received_s - last_sent_s;
    // The rig vents: its states say where the air went, still silent, for [rig_check] vent_s.
    wait_until([] { return false; }, config.rig_check.vent_s);
    RigStateSeen latest;
    if (device.read_rig_state(latest)) seen.after = latest.reading;
  }
  // The engine speaks again (venting if it faulted): the rig must serve it once more.
  device.hold_commands(false);
  const double resumed_s = monotonic_s();
  if (!seen.tripped) (void)core.send(EngineCommand::of(CommandKind::kDisarm));
  seen.served_again = wait_until([&] { return device.last_state_s() > resumed_s; }, config.lcm.connect_timeout_s);
  seen.served_again_s = seen.served_again ? device.last_state_s() - resumed_s : 0.0;
  while (core.poll_event(event)) {
    if (event.kind == EventKind::kFault && seen.engine_fault == FaultCode::kNone) {
      seen.engine_fault = event.fault;
      seen.engine_detail =
          event.detail[0] != '\0' ? std::string(event.detail.data()) : std::string(fault_message(event.fault));
    }
  }
  if (seen.engine_fault == FaultCode::kNone && core.fault() != FaultCode::kNone) seen.engine_fault = core.fault();
  // Leave it as a check leaves everything: vented, the fault (the one provoked) reset.
  if (core.state() == EngineState::kFault) (void)core.send(EngineCommand::of(CommandKind::kReset));
  if (valves_live(core.state())) (void)core.send(EngineCommand::of(CommandKind::kDisarm));
  wait_until([&] { return !valves_live(core.state()) && core.state() != EngineState::kFault; }, 1.0);
  return seen;
}

LimitVerdict judge_command_timeout(const TimeoutObservation& seen, const Configuration& config) {
  const double timeout_s = config.lcm.rig_timeout_s;
  const double tolerance_s = config.rig_check.timeout_tolerance_s;
  LimitVerdict v{"command timeout (provoked)", "",
                 text("a trip within [lcm] rig_timeout_s %.1f ms +- [rig_check] timeout_tolerance_s %.1f ms",
                      timeout_s * 1e3, tolerance_s * 1e3),
                 ""};
  if (!seen.not_provoked.empty()) {
    v.found = "not provoked";
    v.problem = "the command timeout could not be provoked: " + seen.not_provoked;
    return v;
  }
  if (!seen.tripped) {
    v.found = text("no trip in %.0f ms", seen.silent_for_s * 1e3);
    v.problem = text(
        "the rig did not vent by itself: no state with FAULT_COMMAND_TIMEOUT in %.0f ms without commands (this "
        "configuration's [lcm] rig_timeout_s is %.1f ms): its command timeout is missing or longer",
        seen.silent_for_s * 1e3, timeout_s * 1e3);
    return v;
  }
  v.found = text("tripped %.1f ms after the last command", seen.delay_s * 1e3);
  std::vector<std::string> problems;
  const std::int32_t bits = seen.trip.fault_bits;
  if ((bits & io_state_t::FAULT_COMMAND_TIMEOUT) == 0) {
    problems.push_back(
        text("the rig tripped for another reason (fault_bits %d, no FAULT_COMMAND_TIMEOUT) while the engine was silent",
             bits));
  }
  if ((bits & io_state_t::FAULT_NO_SESSION) == 0)
    problems.push_back(text("its trip state lacks FAULT_NO_SESSION (fault_bits %d)", bits));
  if (seen.trip.session_id != seen.session_id) {
    problems.push_back(
        seen.trip.session_id == 0
            ? std::string("its trip state names no session: a tripped rig names the session it dropped for "
                          "[lcm] rig_timeout_s (docs/lcm-protocol.md, rig rule 8a)")
            : text("its trip state names session %lld, not this one (%lld)",
                   static_cast<long long>(seen.trip.session_id), static_cast<long long>(seen.session_id)));
  } else if (seen.trip.command_seq != seen.last_command_seq) {
    problems.push_back(
        text("its trip state carries command_seq %lld, the last command sent was %lld (the tripped state "
             "echoes the last command applied)",
             static_cast<long long>(seen.trip.command_seq), static_cast<long long>(seen.last_command_seq)));
  }
  if (seen.delay_s > timeout_s + tolerance_s) {
    problems.push_back(
        text("it vented %.1f ms after the last command, later than [lcm] rig_timeout_s %.1f ms + [rig_check] "
             "timeout_tolerance_s %.1f ms",
             seen.delay_s * 1e3, timeout_s * 1e3, tolerance_s * 1e3));
  } else if (seen.delay_s < timeout_s - tolerance_s) {
    problems.push_back(
        text("it vented %.1f ms after the last command, earlier than [lcm] rig_timeout_s %.1f ms - [rig_check] "
             "timeout_tolerance_s %.1f ms: it would drop sessions on delays the engine rides through",
             seen.delay_s * 1e3, timeout_s * 1e3, tolerance_s * 1e3));
  }
  const double ambient_bar = config.controller.gas.ambient_bar;
  const double held_bar = excess_bar(seen.before, ambient_bar);
  const double left_bar = excess_bar(seen.after, ambient_bar);
  if (held_bar >= config.rig_check.min_change_bar && left_bar > 0.5 * held_bar) {
    problems.push_back(
        text("it reported the timeout but did not vent: the fuller chamber held %+.3f bar over ambient before "
             "and %+.3f bar %.1f s after",
             held_bar, left_bar, config.rig_check.vent_s));
  }
  if (!seen.served_again) {
    problems.push_back(
        text("it did not serve this engine again within [lcm] connect_timeout_s %.1f s once the commands "
             "resumed: after a trip a rig offers a new binding",
             config.lcm.connect_timeout_s));
  }
  if (seen.engine_fault != FaultCode::kRigTimeout) {
    problems.push_back(std::string("the engine named it ") + fault_name(seen.engine_fault) +
                       ", not rig-timeout (the trip state did " + "not reach it as the rig's own)");
  }
  for (const std::string& p : problems) v.problem += (v.problem.empty() ? "" : "; ") + p;
  return v;
}

nlohmann::json limits_json(const std::vector<LimitVerdict>& verdicts, const RigAnnouncedLimits* announced,
                           const TimeoutObservation* timeout) {
  nlohmann::json out = {{"checks", nlohmann::json::array()}};
  bool all = true;
  for (const LimitVerdict& v : verdicts) {
    out["checks"].push_back(
        {{"name", v.name}, {"found", v.found}, {"expected", v.expected}, {"pass", v.pass()}, {"problem", v.problem}});
    all = all && v.pass();
  }
  out["all_pass"] = all;
  out["announced"] = announced == nullptr
                         ? nlohmann::json(nullptr)
                         : nlohmann::json{{"joints", announced->joints},
                                          {"period_s", announced->period_s},
                                          {"command_timeout_s", announced->command_timeout_s},
                                          {"pressure_ceiling_bar", announced->pressure_ceiling_bar},
                                          {"angle_limit_deg", announced->angle_limit_rad * kDegPerRad}};
  if (timeout != nullptr) {
    const TimeoutObservation& t = *timeout;
    out["timeout"] = {{"provoked", t.not_provoked.empty()},
                      {"tripped", t.tripped},
                      {"delay_s", t.delay_s},
                      {"trip_fault_bits", t.trip.fault_bits},
                      {"trip_session_is_ours", t.trip.session_id == t.session_id},
                      {"trip_command_seq", t.trip.command_seq},
                      {"last_command_seq", t.last_command_seq},
                      {"chambers_before_bar", {t.before.joint[0].chamber_bar[0], t.before.joint[0].chamber_bar[1]}},
                      {"chambers_after_bar", {t.after.joint[0].chamber_bar[0], t.after.joint[0].chamber_bar[1]}},
                      {"served_again", t.served_again},
                      {"served_again_s", t.served_again_s},
                      {"engine_fault", fault_name(t.engine_fault)},
                      {"engine_message", t.engine_detail}};
  }
  return out;
}

}  // namespace bellows
