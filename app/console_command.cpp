#include "app/console_command.hpp"

#include <cstdio>
#include <memory>
#include <ostream>

#include "app/config_file.hpp"
#include "app/console_sessions.hpp"
#include "app/cpu_idle_hold.hpp"
#include "app/run_command.hpp"
#include "app/signals.hpp"
#include "app/trajectory_file.hpp"
#include "devices/simulated_arm.hpp"
#include "engine/engine_core.hpp"
#include "engine/errors.hpp"
#include "ui/console.hpp"

namespace bellows {

int console_command(const ConsoleOptions& options, std::ostream& out) {
  if (options.device != "sim") {
    throw InputError("--device '" + options.device + "': unknown device (known: sim)");
  }
  if (options.stop_after_rises < 1) throw InputError("--stop-after-rises must be at least 1");
  if (options.exit_after_s < 0.0) throw InputError("--exit-after must not be negative");
  const double speed = parse_speed(options.speed);
  const Configuration config = options.config_path.empty() ? Configuration{} : load_config_file(options.config_path);
  const double sample_s = config.timing.sample_s();
  auto load_trajectory = [sample_s, limits = config.trajectory](const std::string& name_or_path) {
    return resolve_trajectory(name_or_path, sample_s, limits);
  };

  StoreSessionGateway sessions(options.device, options.data_dir);
  ui::ConsoleSetup setup;
  std::uint64_t seed = options.seed;
  if (!options.session_dir.empty()) {
    setup.session = sessions.open(options.session_dir);  // InputError: missing, busy or damaged
    setup.trajectory = *setup.session->experiment.trajectory;
    seed = setup.session->seed;  // the same simulated arm it was recorded with
  } else {
    setup.trajectory = load_trajectory(options.trajectory);
  }

  SimulatedArm arm(config.plant, seed);
  EngineCore core(arm, config.controller, config.timing, config.safety);
  const StopSignalTarget stop_target(core);  // SIGINT/SIGTERM/SIGHUP vent at once, from the handler
  RealtimeLoop loop(core, arm, speed);
  setup.core = &core;
  setup.loop = &loop;
  setup.rt_mode = options.rt;
  setup.environment.speed = options.speed;
  setup.environment.config = config;
  setup.environment.load_trajectory = load_trajectory;
  setup.environment.sessions = &sessions;
  setup.environment.device_name = arm.name();
  setup.environment.seed = seed;
  setup.environment.stop_after_rises = options.stop_after_rises;
  setup.stop_flag = &stop_requested();
  setup.exit_after_s = options.exit_after_s;
  setup.allow_colors = !options.no_color;

  // The loop wakes 200 times a second: keep the cores out of deep idle while it runs.
  const CpuIdleHold idle_hold(speed > 0.0 && options.rt != RealtimeMode::kOff);
  const ui::ConsoleReport report = ui::run_console(std::move(setup));
  char line[320];
  std::snprintf(line, sizeof line,
                "bellows console: %.1f s, %d iterations%s; valves vented.\n"
                "loop: %llu ticks, missed %llu, latency p50 %.0f p99 %.0f max %.0f us (%s%s); "
                "console: %llu frames (%.1f/s), UI thread CPU %.1f%%\n",
                report.seconds, report.iterations,
                report.best_rms_deg >= 0.0 ? (", best RMS " + std::to_string(report.best_rms_deg).substr(0, 6) + " deg").c_str() : "",
                static_cast<unsigned long long>(report.ticks), static_cast<unsigned long long>(report.loop.missed),
                report.loop.p50_us, report.loop.p99_us, report.loop.max_us, loop.rt_description().c_str(),
                idle_hold.held_us() ? ", cores out of deep idle" : "",
                static_cast<unsigned long long>(report.frames),
                report.seconds > 0 ? static_cast<double>(report.frames) / report.seconds : 0.0,
                report.seconds > 0 ? 100.0 * report.ui_cpu_s / report.seconds : 0.0);
  out << line;
  if (!report.save_status.empty()) out << "session: " << report.save_status << " (saved as it went)\n";
  if (!report.unsaved.empty()) out << "bellows: not saved: " << report.unsaved << "\n";
  if (report.missed_warnings > 0) {
    out << "loop: " << report.missed_warnings
        << " deadlines missed, counted as warnings (the simulated arm's time follows the engine's ticks)\n";
  }
  if (report.dropped_events > 0) out << "bellows: " << report.dropped_events << " engine events dropped (the event queue was full)\n";
  out << std::flush;
  if (report.stopped_by_signal) return 128 + stop_signal();
  return 0;
}

}  // namespace bellows
