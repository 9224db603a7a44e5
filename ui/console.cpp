#include "ui/console.hpp"

#include <algorithm>
#include <clocale>
#include <ctime>

#include "ui/frame_pacer.hpp"
#include "ui/keys.hpp"
#include "ui/render.hpp"
#include "ui/stderr_capture.hpp"
#include "ui/terminal.hpp"

namespace bellows::ui {
namespace {

constexpr int kKeyTimeoutMs = 33;
constexpr double kDisarmWaitS = 1.0;              // on quit: how long the engine may take to disarm
constexpr double kFinalSaveWaitS = 10.0;          // on exit: how long the last autosave may take
constexpr std::size_t kTelemetryCapacity = 4096;  // ~20 s of ticks at 200 Hz between two frames

double seconds_of(clockid_t clock) {
  timespec t{};
  clock_gettime(clock, &t);
  return static_cast<double>(t.tv_sec) + static_cast<double>(t.tv_nsec) * 1e-9;
}
double monotonic_s() { return seconds_of(CLOCK_MONOTONIC); }

/// Stops the engine loop (which vents) however the console ends.
struct LoopStopper {
  RealtimeLoop* loop;
  ~LoopStopper() {
    if (loop != nullptr) loop->stop();
  }
};

/// Engine time on the simulated clock, ticked on the UI thread while the controller needs it:
/// `speed` times the wall time since the last call (0: as fast as it can), never more ticks than
/// the telemetry tap holds before the controller drains it, nor more than a frame's wall time.
class SimulatedTime {
 public:
  SimulatedTime(SimulatedClock& clock, const TelemetryRing& tap, double speed)
      : clock_(clock), tap_(tap), speed_(speed) {}

  /// True if engine time passed.
  bool advance(const ConsoleController& controller, double now_s) {
    const double since_s = last_s_ < 0.0 ? 0.0 : now_s - last_s_;
    last_s_ = now_s;
    if (!controller.needs_engine_time()) {
      owed_ticks_ = 0.0;  // idle time is not made up later
      return false;
    }
    const double tick_s = clock_.core().timing().tick_s;
    owed_ticks_ = speed_ > 0.0 ? std::min(owed_ticks_ + since_s * speed_ / tick_s, kMostTicksOwed) : kMostTicksOwed;
    const double until_s = now_s + kLongestStepS;
    long stepped = 0;
    while (stepped < static_cast<long>(owed_ticks_) && controller.needs_engine_time() && tap_.write_available() > 0) {
      clock_.step(1);
      if (++stepped % 64 == 0 && monotonic_s() > until_s) break;  // keys and the screen keep up
    }
    owed_ticks_ = speed_ > 0.0 ? std::max(0.0, owed_ticks_ - static_cast<double>(stepped)) : 0.0;
    if (speed_ > 0.0 && stepped == 0) owed_ticks_ = std::max(owed_ticks_, 1.0);  // a command waits at most a frame
    return stepped > 0;
  }
  /// Whether keys should be read without waiting (time is owed at full speed).
  bool hurried(const ConsoleController& controller) const { return speed_ <= 0.0 && controller.needs_engine_time(); }

 private:
  static constexpr double kLongestStepS = 0.02;
  static constexpr double kMostTicksOwed = 4096.0;
  SimulatedClock& clock_;
  const TelemetryRing& tap_;
  double speed_;
  double last_s_ = -1.0;
  double owed_ticks_ = 0.0;
};

}  // namespace

ConsoleReport run_console(ConsoleSetup setup) {
  std::setlocale(LC_ALL, "");
  // Numbers are read, shown and written with a decimal point whatever the operator's locale: a
  // decimal comma would refuse "0.45" in the prompts and write "t=6363,415" into the session's log.
  std::setlocale(LC_NUMERIC, "C");
  const bool unicode = locale_is_utf8();

  ConsoleEnvironment env = std::move(setup.environment);
  env.core = setup.core;
  env.telemetry = &setup.core->add_telemetry_tap(kTelemetryCapacity);  // before the loop starts
  RealtimeLoop* loop = setup.loop;
  std::optional<SimulatedTime> simulated;
  if (setup.simulated_clock != nullptr) {
    loop = nullptr;  // the UI thread ticks the engine: no latency to measure, no heartbeat
    env.simulated_clock = true;
    simulated.emplace(*setup.simulated_clock, *env.telemetry, env.speed == "max" ? 0.0 : std::stod(env.speed));
  } else {
    env.latency = [loop] { return loop->latency(); };
  }

  // Declared before the loop stopper: the controller owns the buffers of a running trial, so it
  // must outlive the engine loop however this function ends.
  std::optional<ConsoleController> controller;
  StderrCapture device_lines;  // declared before the terminal: given back after the screen is
  std::optional<Terminal> terminal;
  terminal.emplace(setup.allow_colors);  // throws InputError without a terminal, before the loop runs
  try {
    if (loop != nullptr) loop->start(setup.rt_mode);
  } catch (...) {
    terminal.reset();  // the error must reach a normal screen
    throw;
  }
  LoopStopper stopper{loop};
  env.rt_description = loop != nullptr ? loop->rt_description() : std::string();
  controller.emplace(std::move(env), std::move(setup.trajectory), unicode);
  if (setup.session) controller->adopt_session(std::move(*setup.session));

  ConsoleReport report;
  report.unicode = unicode;
  report.colors = terminal->colors();
  const double start_s = monotonic_s();
  const double cpu_start_s = seconds_of(CLOCK_THREAD_CPUTIME_ID);
  controller->resize(terminal->width(), terminal->height());
  controller->start(start_s);
  Canvas canvas(terminal->width(), terminal->height());
  FramePacer pacer;
  std::uint64_t repaints_done = 0;

  while (!controller->quit_requested()) {
    int key = terminal->read_key(simulated && simulated->hurried(*controller) ? 0 : kKeyTimeoutMs);
    for (int extra = 0; key != key::kNone && extra < 64; ++extra) {  // every key typed ahead, then draw
      if (key == key::kResize) {
        controller->resize(terminal->width(), terminal->height());
        canvas = Canvas(terminal->width(), terminal->height());
      }
      controller->handle_key(key, monotonic_s());
      if (controller->quit_requested()) break;
      key = terminal->read_key(0);
    }
    const double now = monotonic_s();
    for (std::string& line : device_lines.drain()) controller->device_said(std::move(line));
    controller->update(now);
    if (simulated && simulated->advance(*controller, now)) controller->update(monotonic_s());
    if (setup.stop_flag != nullptr && setup.stop_flag->load(std::memory_order_relaxed)) {
      // The handler has latched the stop already (the valves vent in the next tick); this logs it.
      controller->emergency_stop("signal: emergency stop, save and exit");
      report.stopped_by_signal = true;
      break;
    }
    if (setup.exit_after_s > 0.0 && now - start_s >= setup.exit_after_s) {
      report.exited_after_time = true;
      break;
    }
    if (controller->repaints() != repaints_done) {
      repaints_done = controller->repaints();
      terminal->repaint();
    }
    if (pacer.should_draw(now, controller->revision(), controller->active())) {
      render(controller->state(), canvas);
      terminal->draw(canvas);
      ++report.frames;
    }
  }

  // Vent: disarm through the engine (heartbeats continue meanwhile), then stop the loop.
  // (A quit from the keyboard has sent the disarm already; a signal has stopped the engine.)
  if (report.exited_after_time && valves_live(setup.core->state()) &&
      !setup.core->send(EngineCommand::of(CommandKind::kDisarm))) {
    setup.core->request_emergency_stop();  // the queue is full: vent through the latch
  }
  const double quit_s = monotonic_s();
  while (valves_live(setup.core->state()) && monotonic_s() - quit_s < kDisarmWaitS) {
    terminal->read_key(10);
    if (setup.simulated_clock != nullptr) setup.simulated_clock->step(1);  // the disarm's tick
    controller->update(monotonic_s());
  }
  if (valves_live(setup.core->state())) setup.core->request_emergency_stop();  // never leave them live
  if (setup.simulated_clock != nullptr && !setup.core->emergency_stop_delivered()) setup.simulated_clock->step(1);
  // Vented; now what is not on disk yet (the last log lines, a black box) goes there.
  for (std::string& line : device_lines.drain()) controller->device_said(std::move(line));
  while (!controller->saves_settled() && monotonic_s() - quit_s < kFinalSaveWaitS) {
    terminal->read_key(10);
    controller->update(monotonic_s());
  }
  report.unsaved = controller->unsaved_work();
  // "saved as it went" only when everything is on disk: a failed save is never reported as saved.
  report.save_status = controller->saves_settled() && report.unsaved.empty()
                           ? controller->state().experiment.session_location
                           : std::string();
  report.unsaved_work_lost = controller->quitting_loses_work();
  report.seconds = monotonic_s() - start_s;
  report.ui_cpu_s = seconds_of(CLOCK_THREAD_CPUTIME_ID) - cpu_start_s;
  if (loop != nullptr) loop->stop();
  terminal.reset();
  device_lines.restore();  // the device's last words (the link's final vent), on the normal screen
  if (loop != nullptr) report.loop = loop->latency();
  report.ticks = setup.core->ticks();
  report.dropped_events = setup.core->dropped_events();
  report.missed_warnings = setup.core->missed_deadline_warnings();
  report.iterations = static_cast<int>(controller->state().experiment.trials.size());
  report.best_rms_deg = controller->state().experiment.best_rms_deg();
  return report;
}

}  // namespace bellows::ui
