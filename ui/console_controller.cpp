#include "ui/console_controller.hpp"

#include <algorithm>
#include <cmath>
#include <ctime>
#include <limits>
#include <numbers>

#include <time.h>

#include "engine/base/errors.hpp"
#include "ui/canvas.hpp"
#include "ui/joint_view.hpp"

namespace bellows::ui {
namespace {

constexpr double kHeartbeatPeriodS = 0.05;  // well inside the engine's timeout (1 s by default)
constexpr double kLoopStatsPeriodS = 0.25;  // the latency summary walks a histogram: not every frame
constexpr double kStaleSnapshotS = 0.5;     // no fresh tick for this long: the device shows no data
constexpr double kStripSeconds = 5.0;       // the live plot's window
constexpr double kStopOverdueS = 0.5;       // an unacted stop this old is shown as overdue (100 ticks)
constexpr const char* kStopOverdueText =
    "EMERGENCY STOP requested: the engine has not acted on it yet (is its loop stalled?)";

std::string system_clock_text() {
  const std::time_t now = std::time(nullptr);
  std::tm local{};
  localtime_r(&now, &local);
  char text[16];
  std::strftime(text, sizeof text, "%H:%M:%S", &local);
  return text;
}

}  // namespace

ConsoleController::ConsoleController(ConsoleEnvironment env, Trajectory trajectory, bool unicode)
    : env_(std::move(env)),
      model_(discretize_arm_model(env_.config.model, env_.config.timing.sample_s())),
      runner_(*env_.core, env_.config.timing),
      diagnostics_(env_.config.controller.p_max_bar - env_.config.controller.gas.ambient_bar) {
  if (!env_.clock_text) env_.clock_text = system_clock_text;
  state_.unicode = unicode;
  state_.config = env_.config;
  state_.device.name = env_.device_name;
  state_.loop.rt = env_.rt_description;
  state_.loop.speed = env_.speed;
  state_.loop.tick_hz = 1.0 / env_.config.timing.tick_s;
  state_.loop.realtime = static_cast<bool>(env_.latency);
  state_.loop.clock = env_.simulated_clock ? "sim" : "wall";
  state_.law_name = env_.config.ilc.law;
  state_.stop_after_rises = env_.stop_after_rises;
  state_.sessions_available = env_.sessions != nullptr && env_.sessions->available();
  state_.sessions_unavailable_reason =
      env_.sessions != nullptr ? env_.sessions->unavailable_reason() : "no session store in this build";
  auto shared = std::make_shared<const Trajectory>(std::move(trajectory));
  state_.experiment = Experiment::start(shared);
  ++experiment_serial_;
  const auto strip_size = static_cast<std::size_t>(std::lround(kStripSeconds / env_.config.timing.sample_s()));
  strip_time_.assign(strip_size, 0.0);
  strip_angle_.assign(strip_size, {});
  strip_setpoint_.assign(strip_size, {});
}

ConsoleController::~ConsoleController() = default;

bool ConsoleController::active() const {
  return state_.run.mode != RunProgress::Mode::kIdle || state_.engine_state == EngineState::kRunning;
}

void ConsoleController::log(LogSource source, std::string text, bool important, double engine_time_s, bool routine) {
  if (engine_time_s < -1.0) {
    // The newest engine time the console knows: an event polled in this update may be newer than
    // the last snapshot, and the log's times never run backwards.
    engine_time_s = state_.live_valid ? std::max(state_.live.time_s, newest_event_s_) : newest_event_s_;
  }
  state_.log.add({env_.clock_text(),
                  engine_time_s,
                  source,
                  std::move(text),
                  important,
                  routine,
                  utc_timestamp(),
                  state_.experiment.next_iteration(),
                  {}});
  ++revision_;
}

void ConsoleController::log_event(const char* kind, LogSource source, std::string text) {
  log(source, std::move(text));
  state_.log.set_last_event_kind(kind);
}

void ConsoleController::device_said(std::string line) {
  constexpr std::string_view kPrefix = "bellows: ";  // the program's name, which a log line needs not
  if (line.rfind(kPrefix, 0) == 0) line.erase(0, kPrefix.size());
  log(LogSource::kDevice, std::move(line));
}

void ConsoleController::set_status(std::string text, bool important) {
  state_.status = std::move(text);
  state_.status_important = important;
  state_.status_screen = state_.screen;  // a key's message moves with the screen the key leads to (handle_key)
  ++status_serial_;
  ++revision_;
}

bool ConsoleController::needs_engine_time() const {
  if (env_.core->state() == EngineState::kRunning || !env_.core->emergency_stop_delivered()) return true;
  if (static_cast<long long>(env_.core->ticks()) <= action_sent_at_tick_) return true;
  return valve_test_ != nullptr && valve_test_->running();
}

bool ConsoleController::send(const EngineCommand& command, const char* what) {
  const CommandKind k = command.kind;
  const bool setting =
      k == CommandKind::kSelectTrajectory || k == CommandKind::kSetGains || k == CommandKind::kHeartbeat;
  if (!setting) note_action_sent();
  if (env_.core->send(command)) return true;
  log(LogSource::kOperator, std::string("command queue full: ") + what + " not sent", true);
  set_status(std::string("the engine's command queue is full: ") + what + " not sent", true);
  return false;
}

bool ConsoleController::send_simple(CommandKind kind, const char* what) { return send(EngineCommand::of(kind), what); }

void ConsoleController::send_gains() {
  const ControllerParameters& c = state_.config.controller;
  EngineCommand gains = EngineCommand::of(CommandKind::kSetGains);
  gains.gains = {c.k_ff, c.k_p, c.k_i_per_s, c.k_d_s};
  if (!send(gains, "set gains")) log(LogSource::kOperator, "the engine keeps its previous gains", true);
}

void ConsoleController::start(double now_s) {
  now_s_ = now_s;
  env_.core->monitor_heartbeat(!env_.simulated_clock);
  heartbeat(now_s);
  if (selected_trajectories_.empty() || selected_trajectories_.back() != state_.experiment.trajectory) {
    select_trajectory(state_.experiment.trajectory);
  }
  send_gains();
  rebuild_law();
  log(LogSource::kOperator, format("console started: device %s, %s clock, speed x%s, trajectory %s",
                                   env_.device_name.c_str(), env_.simulated_clock ? "simulated" : "wall",
                                   env_.speed.c_str(), state_.experiment.trajectory->name.c_str()));
  if (!env_.model_note.empty()) log(LogSource::kOperator, env_.model_note);  // saved with the session
  set_status("a arms the valves, t chooses a trajectory, ? lists every key");
}

void ConsoleController::select_trajectory(std::shared_ptr<const Trajectory> trajectory) {
  selected_trajectories_.push_back(std::move(trajectory));
  if (!send(EngineCommand::select_trajectory(*selected_trajectories_.back()), "select trajectory")) {
    selected_trajectories_.pop_back();  // the engine never saw it
    log(LogSource::kOperator, "the engine holds the previous trajectory until the next trial", true);
  }
}

void ConsoleController::heartbeat(double now_s) {
  if (env_.simulated_clock) return;  // not monitored: heartbeats would only fill a queue no tick empties
  if (state_.heartbeat_drill) {
    const double waited = now_s - drill_started_s_;
    if (state_.engine_state == EngineState::kFault) {
      state_.heartbeat_drill = false;
      log(LogSource::kOperator, format("heartbeat drill: the engine vented after %.1f s without heartbeat (%s)", waited,
                                       fault_name(state_.fault)));
    } else if (waited > env_.config.safety.heartbeat_timeout_s + 3.0) {
      state_.heartbeat_drill = false;
      log(LogSource::kOperator, format("heartbeat drill FAILED: the engine did not vent within %.1f s", waited), true);
    } else {
      return;
    }
  }
  if (last_heartbeat_s_ >= 0.0 && now_s - last_heartbeat_s_ < kHeartbeatPeriodS) return;
  if (env_.core->send(EngineCommand::of(CommandKind::kHeartbeat))) last_heartbeat_s_ = now_s;
}

void ConsoleController::update(double now_s) {
  now_s_ = now_s;
  heartbeat(now_s);
  poll_engine(now_s);
  refresh_rig(now_s);  // the link's figures before the health line uses them
  poll_snapshot_and_telemetry(now_s);
  if (continue_pending_) {
    poll_engine(now_s);  // the events the engine emitted with the trial's end come first
    continue_pending_ = false;
    continue_run();
  }
  poll_tasks();
  if (black_box_pending_ && env_.core->black_box().frozen()) {
    state_.fault_view.black_box = env_.core->black_box().copy_frozen();
    black_box_pending_ = false;
    if (!state_.fault_view.black_box.empty()) {
      state_.fault_view.where = fault_location(state_.fault_view.code, state_.fault_view.joint,
                                               state_.fault_view.black_box.back(), state_.config);
      if (!state_.fault_view.where.empty()) {
        log(LogSource::kEngine,
            format("%s fired on %s", fault_name(state_.fault_view.code), state_.fault_view.where.c_str()), true,
            state_.fault_view.time_s);
      }
    }
    if (!state_.fault_view.black_box.empty()) {  // kept for the session, saved with the next save
      state_.experiment.faults.push_back(
          {fault_name(state_.fault_view.code), state_.experiment.next_iteration(), state_.fault_view.black_box});
    }
    ++revision_;
  }
  if (env_.latency && (last_loop_stats_s_ < 0.0 || now_s - last_loop_stats_s_ >= kLoopStatsPeriodS)) {
    last_loop_stats_s_ = now_s;
    const LatencySummary l = env_.latency();
    state_.loop.missed = l.missed;
    state_.loop.p50_us = l.p50_us;
    state_.loop.p99_us = l.p99_us;
    state_.loop.max_us = l.max_us;
  }
  state_.loop.ticks = env_.core->ticks();
  state_.loop.dropped_telemetry = env_.core->dropped_telemetry();
  if (const std::uint64_t dropped = env_.core->dropped_events(); dropped != state_.loop.dropped_events) {
    log(LogSource::kEngine,
        format("%llu engine events dropped (the event queue was full)",
               static_cast<unsigned long long>(dropped - state_.loop.dropped_events)),
        true);
    state_.loop.dropped_events = dropped;
  }
  if (stop_pending_) {
    if (env_.core->emergency_stop_delivered()) {
      on_emergency_stop_delivered();
    } else if (now_s - stop_requested_s_ > kStopOverdueS && state_.status != kStopOverdueText) {
      set_status(kStopOverdueText, true);  // never "vented" for a stop the engine has not acted on
    }
  }
  autosave();
}

void ConsoleController::on_emergency_stop_delivered() {
  stop_pending_ = false;
  log(LogSource::kEngine, "emergency stop: valves vented", true);
  set_status("EMERGENCY STOP: valves vented. R resets.", true);
}

void ConsoleController::poll_engine(double /*now_s*/) {
  EngineEvent event;
  while (env_.core->poll_event(event)) {
    on_event(event);
    if (in_flight_ && runner_.observe(event)) on_trial_moved();
  }
  const EngineState engine = env_.core->state();
  if (engine != state_.engine_state) {
    state_.engine_state = engine;
    ++revision_;
  }
  state_.fault = env_.core->fault();
}

void ConsoleController::on_event(const EngineEvent& event) {
  forward_to_valve_test(event);
  newest_event_s_ = std::max(newest_event_s_, event.time_s);
  switch (event.kind) {
    case EventKind::kStateChanged:
      state_.engine_state = event.to;
      {
        // A trial's own ARMED <-> RUNNING changes (its start, its end) are routine: the trial's lines say it better.
        const bool routine = (event.command == CommandKind::kStartTrial && event.to == EngineState::kRunning) ||
                             event.command == CommandKind::kTrialEnd;
        // Into FAULT: the fault's own name (a guard is not an emergency stop); else the engine's cause.
        const char* cause = event.to == EngineState::kFault && event.fault != FaultCode::kNone
                                ? fault_name(event.fault)
                                : to_string(event.command);
        log(LogSource::kEngine, format("%s -> %s (%s)", to_string(event.from), to_string(event.to), cause),
            event.to == EngineState::kFault, event.time_s, routine);
      }
      if (event.command == CommandKind::kArm && event.to == EngineState::kArmed) {
        set_status("armed: r runs a trial, n learns and runs, N runs K iterations, Space stops");
      } else if (event.command == CommandKind::kDisarm && event.to == EngineState::kSafe) {
        set_status("disarmed: the valves are vented (a arms again)");
      }
      return;
    case EventKind::kCommandRefused:
      log(LogSource::kEngine, format("refused %s: %s", to_string(event.command), event.refusal), true, event.time_s);
      set_status(format("the engine refused %s: %s", to_string(event.command), event.refusal), true);
      return;
    case EventKind::kFault:
      state_.fault = event.fault;
      state_.fault_view = FaultView{
          event.fault,
          event.time_s,
          {},
          {},
          event.fault_joint,
          event.detail[0] != '\0' ? std::string(event.detail.data()) : std::string(fault_message(event.fault))};
      black_box_pending_ = true;
      log(LogSource::kEngine, format("FAULT %s: %s", fault_name(event.fault), state_.fault_view.detail.c_str()), true,
          event.time_s);
      set_status(format("FAULT %s: %s. R resets.", fault_name(event.fault), state_.fault_view.detail.c_str()), true);
      interrupt_dialog(format("the fault %s", fault_name(event.fault)));
      state_.screen = Screen::kFault;
      if (stop_pending_ && env_.core->emergency_stop_delivered()) on_emergency_stop_delivered();
      return;
    case EventKind::kWarning:
      if (event.fault == FaultCode::kMissedDeadlines) {
        log(LogSource::kEngine,
            format("warning: %u deadlines missed in a row (the machine is loaded); on the simulated arm time follows "
                   "the engine's ticks, so nothing physical is harmed: counted, not a fault",
                   event.count),
            true, event.time_s);
      } else {
        log(LogSource::kEngine, format("warning: %s", fault_message(event.fault)), true, event.time_s);
      }
      return;
    case EventKind::kTrajectorySelected: {
      // The engine holds this one now: every trajectory given before it is handed back.
      const auto held = std::find_if(selected_trajectories_.begin(), selected_trajectories_.end(),
                                     [&](const auto& t) { return t.get() == event.trajectory; });
      if (held != selected_trajectories_.end()) selected_trajectories_.erase(selected_trajectories_.begin(), held);
      return;
    }
    case EventKind::kTrialComplete:  // the trial runner's (poll_engine)
    case EventKind::kTrialAborted:
    case EventKind::kValvePulseDone:  // the valve test's (forwarded above)
      return;
  }
}

void ConsoleController::poll_snapshot_and_telemetry(double now_s) {
  TickRecord tick;
  if (env_.core->read_snapshot(tick)) {
    state_.live = tick;
    state_.live_valid = true;
    last_fresh_snapshot_s_ = now_s;
  }
  // Device health from what the sensors say.
  DeviceHealth health{env_.device_name, false, "no data"};
  // On the simulated clock the reading stands still while no time passes: not stale.
  if (state_.live_valid && (env_.simulated_clock || now_s - last_fresh_snapshot_s_ <= kStaleSnapshotS)) {
    const SensorReading& r = state_.live.reading;
    bool finite = std::isfinite(r.supply_bar);
    for (int j = 0; j < std::clamp(r.joint_count, 1, kMaxJoints); ++j) {
      const JointReading& joint = r.joint[static_cast<std::size_t>(j)];
      finite = finite && std::isfinite(joint.angle_rad) && std::isfinite(joint.chamber_bar[0]) &&
               std::isfinite(joint.chamber_bar[1]);
    }
    if (!finite) {
      health.status = "sensor not a number";
    } else if (r.supply_bar < env_.config.safety.supply_min_bar) {
      health.status = format("supply low (%.2f bar)", r.supply_bar);
    } else {
      health = {env_.device_name, true, "ok"};
    }
  }
  add_link_health(health);
  if (health.ok != state_.device.ok || health.status != state_.device.status) {
    state_.device = health;
    ++revision_;
  }
  if (in_flight_ && runner_.observe(state_.live)) on_trial_moved();
  // The live strip, decimated to the ILC rate.
  if (env_.telemetry != nullptr) {
    const int per_sample = env_.config.timing.ticks_per_sample;
    env_.telemetry->consume_all([&](const TickRecord& t) {
      if (per_sample > 0 && t.tick % static_cast<std::uint64_t>(per_sample) != 0) return;
      strip_time_[strip_next_] = t.time_s;
      for (int j = 0; j < kMaxJoints; ++j) {
        const auto i = static_cast<std::size_t>(j);
        strip_angle_[strip_next_][i] = t.reading.joint[i].angle_rad * 180.0 / std::numbers::pi;
        // Vented, the engine's last set point is none (the plot leaves the gap).
        strip_setpoint_[strip_next_][i] = valves_live(t.state) ? tick_desired_rad(t, j) * 180.0 / std::numbers::pi
                                                               : std::numeric_limits<double>::quiet_NaN();
      }
      strip_next_ = (strip_next_ + 1) % strip_time_.size();
      strip_count_ = std::min(strip_count_ + 1, strip_time_.size());
      ++strip_revision_;
    });
    if (strip_revision_ != strip_exported_) export_strip();
  }
}

void ConsoleController::export_strip() {
  strip_exported_ = strip_revision_;
  const auto joint = static_cast<std::size_t>(std::clamp(state_.joint, 0, kMaxJoints - 1));
  LiveStrip& s = state_.strip;
  s.time_s.resize(strip_count_);
  s.angle_deg.resize(strip_count_);
  s.setpoint_deg.resize(strip_count_);
  if (strip_count_ == 0) return;
  const std::size_t first = (strip_next_ + strip_time_.size() - strip_count_) % strip_time_.size();
  const double newest_s = strip_time_[(strip_next_ + strip_time_.size() - 1) % strip_time_.size()];
  for (std::size_t i = 0; i < strip_count_; ++i) {
    const std::size_t j = (first + i) % strip_time_.size();
    s.time_s[i] = strip_time_[j] - newest_s;  // seconds before now
    s.angle_deg[i] = strip_angle_[j][joint];
    s.setpoint_deg[i] = strip_setpoint_[j][joint];
  }
}

void ConsoleController::emergency_stop(const std::string& why) {
  // The latch, not the queue: however full the command queue, the next tick vents. No waiting here.
  env_.core->request_emergency_stop();
  stop_pending_ = true;
  stop_requested_s_ = now_s_;
  if (state_.run.mode != RunProgress::Mode::kIdle) state_.run.stop_requested = true;
  if (valve_test_ && valve_test_->running()) {
    valve_test_->abandon("emergency stop");
    show_valve_verdicts();
  }
  interrupt_dialog("the emergency stop");
  log(LogSource::kOperator, why, true);
  set_status("EMERGENCY STOP requested: venting", true);
}

void ConsoleController::resize(int width, int height) {
  state_.width = width;
  state_.height = height;
  ++revision_;
}

}  // namespace bellows::ui
