#include "app/console_command.hpp"

#include <any>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <optional>
#include <ostream>

#include "app/config_file.hpp"
#include "app/console_sessions.hpp"
#include "app/run_recording.hpp"
#include "app/device_factory.hpp"
#include "app/learning_model.hpp"
#include "app/rig_profile_write.hpp"
#include "sessions/session_store.hpp"
#include "app/plot_console.hpp"
#include "app/cpu_idle_hold.hpp"
#include "app/run_command.hpp"
#include "app/signals.hpp"
#include "app/trajectory_file.hpp"
#include "devices/simulated_arm.hpp"
#include "engine/rt/engine_core.hpp"
#include "engine/rt/engine_driver.hpp"
#include "engine/base/errors.hpp"
#include "engine/base/iteration_numbering.hpp"
#include "ui/console.hpp"

namespace bellows {

namespace {

// A session reopens on the device and the arm it was recorded on (unless --device names one): its [device]
// and [arm] sections and its manifest's device. Says why when that device cannot be driven from here.
void take_rig_of_session(const std::string& session_dir, const ConsoleOptions& options, Configuration& config) {
  std::filesystem::path data_dir;
  try {
    data_dir = default_data_dir();
  } catch (const InputError&) {
    // Without a data directory the session is a path; resolve_session_dir says so otherwise.
  }
  const std::filesystem::path directory = resolve_session_dir(session_dir, data_dir);
  const SessionManifest manifest = load_manifest(directory);
  if (!options.device.kind.empty() && options.device.kind != manifest.device) {
    throw InputError("session " + directory.string() + " was recorded on the device '" + manifest.device +
                     "'; --device " + options.device.kind + " cannot continue it (leave --device out to reopen it on " +
                     manifest.device + ")");
  }
  config.device = manifest.configuration.device;
  config.device.kind = manifest.device;
  // The arm too: a session of arm2 continues on arm2 (its trajectory and corrections have its joints).
  const ArmParameters& recorded = manifest.configuration.arm;
  if (config.arm.has_chain() && config.arm.name() != recorded.name()) {
    throw InputError("session " + directory.string() + " was recorded on the arm '" +
                     (recorded.has_chain() ? recorded.name() : std::string("of one joint")) + "'; --config names '" +
                     config.arm.name() + "' (leave [arm] out to reopen it on its own arm)");
  }
  config.arm = recorded;
  // And its ticks: telemetry of other ticks would not fit the session's files (ui adopt() refuses it).
  const TimingParameters& timing = manifest.configuration.timing;
  const auto format_number = [](double value) {
    char text[32];
    std::snprintf(text, sizeof text, "%g", value);
    return std::string(text);
  };
  if (!options.config_path.empty() && !config.timing.same_ticks(timing)) {
    throw InputError("session " + directory.string() +
                     " was recorded at [timing] tick_s = " + format_number(timing.tick_s) + " s, ticks_per_sample = " +
                     std::to_string(timing.ticks_per_sample) + "; --config has " + format_number(config.timing.tick_s) +
                     " s, " + std::to_string(config.timing.ticks_per_sample) + " (set them as recorded to reopen it)");
  }
  config.timing.tick_s = timing.tick_s;
  config.timing.ticks_per_sample = timing.ticks_per_sample;
}

}  // namespace

int console_command(const ConsoleOptions& options, std::ostream& out) {
  if (options.stop_after_rises < 1) throw InputError("--stop-after-rises must be at least 1");
  if (options.exit_after_s < 0.0) throw InputError("--exit-after must not be negative");
  const double speed = parse_speed(options.speed);
  Configuration config = options.config_path.empty() ? Configuration{} : load_config_file(options.config_path);
  if (!options.session_dir.empty()) take_rig_of_session(options.session_dir, options, config);
  config.device = resolve_device(options.device, config.device);
  if (options.clock != "wall") resolve_clock(options.clock, config.device.kind);  // sim: the simulated arm only
  const bool simulated_time = options.clock == "sim";
  // The model the learning uses: the rig profile's identified one, if it has one (a reopened session
  // too: it keeps its gains and law, the model is the rig's as it is now).
  const LearningModel learning_model = choose_learning_model(config, config.device);
  config.model = learning_model.model;
  const double sample_s = config.timing.sample_s();
  auto load_trajectory = [sample_s, limits = config.trajectory, arm = config.arm](const std::string& name_or_path) {
    Trajectory trajectory = resolve_trajectory(name_or_path, sample_s, limits);
    require_driven_joints(trajectory, arm);  // the --trajectory at start and every one the chooser offers
    return trajectory;
  };

  // The seed first (a session continues on the simulated arm it was recorded with), then the device.
  std::uint64_t seed = options.seed;
  std::optional<ui::SessionSnapshot> opened_session;
  {
    StoreSessionGateway reader(config.device.kind, nlohmann::ordered_json::object(), options.data_dir);
    if (!options.session_dir.empty()) {
      opened_session = reader.open(options.session_dir);  // InputError: missing, busy or damaged
      seed = opened_session->seed;
    }
  }
  std::unique_ptr<OpenedDevice> rig;
  try {
    rig = open_device(config.device, config, seed, options.rt, 0,
                      std::filesystem::path(options.config_path).parent_path());
  } catch (const BellowsError& error) {
    if (options.session_dir.empty()) throw;
    throw InputError("session " + options.session_dir + " was recorded on the device '" + config.device.kind +
                     "', which this console cannot drive now: " + error.what());
  }
  if (rig->needs_real_time() && speed != 1.0) {
    throw InputError("--device " + config.device.kind + " runs in real time: --speed must be 1");
  }
  struct StopRig {  // the device's I/O thread: its last vent goes out after the loop stopped
    OpenedDevice& rig;
    ~StopRig() { rig.stop(); }
  } stop_rig{*rig};

  StoreSessionGateway sessions(config.device.kind, rig->session_info(), options.data_dir, learning_model.source);
  ui::ConsoleSetup setup;
  if (opened_session) {
    setup.session = sessions.open(options.session_dir);  // this gateway saves into it from now on
    setup.trajectory = *setup.session->experiment.trajectory;
    require_driven_joints(setup.trajectory, config.arm);  // a session of another arm: one line, nothing driven
  } else {
    setup.trajectory = load_trajectory(options.trajectory);
  }

  Device& device = rig->device();
  EngineCore core(device, config.controller, config.timing, config.safety);
  const StopSignalTarget stop_target(core);  // SIGINT/SIGTERM/SIGHUP/SIGQUIT vent at once, from the handler
  RealtimeLoop loop(core, device, speed);
  SimulatedClock simulated_clock(core, device);  // --clock sim: the UI thread ticks it (as bellows run does)
  setup.core = &core;
  setup.loop = &loop;
  if (simulated_time) setup.simulated_clock = &simulated_clock;
  setup.rt_mode = options.rt;
  setup.environment.speed = options.speed;
  setup.environment.config = config;
  setup.environment.load_trajectory = load_trajectory;
  setup.environment.sessions = &sessions;
  setup.environment.device_name = device.name();
  setup.environment.device_where = rig->where();
  setup.environment.rig_profile = rig->rig_profile_name();
  setup.environment.model_note = learning_model_line(learning_model);
  setup.environment.device_health = [&device] { return device.health(); };
  setup.environment.raw_inputs = [&device] { return device.raw_inputs(); };
  if (config.device.kind == "t7" && !config.device.rig_profile.empty()) {
    setup.environment.zero_angle = [&opened = *rig, path = config.device.rig_profile](double read_rad) {
      return zero_rig_angle(opened, path, read_rad);
    };
  }
  setup.environment.write_figures = [root = default_figures_root(), &sessions](const std::string& location,
                                                                               int iterations) {
    return write_console_figures(location, iterations, root,
                                 [&sessions](const std::function<void()>& read) { sessions.read_quietly(read); });
  };
  if (simulated_time) {
    setup.environment.capture_trial_end = [&core, &opened = *rig, &simulated_clock] {
      return std::any(
          capture_resume_state(core, opened.simulated_arm(), opened.simulated_arm_chain(), &simulated_clock));
    };
  }
  if (simulated_time && setup.session) {
    const std::string location = setup.session->experiment.session_location;
    setup.environment.arm_where_saved = [&core, &opened = *rig, &simulated_clock, location]() -> std::string {
      const SessionManifest manifest = load_manifest(location);
      if (!can_restore_exactly(manifest))
        return "the session holds no engine state to continue from (recorded on the wall clock)";
      if (core.ticks() != 0) return "the engine has run since the session was opened";
      restore_resume_state(manifest, opened.simulated_arm(), opened.simulated_arm_chain(), core, &simulated_clock,
                           "session " + location + ": manifest.json");
      return "";
    };
  }
  setup.environment.seed = seed;
  setup.environment.stop_after_rises = options.stop_after_rises;
  setup.stop_flag = &stop_requested();
  setup.exit_after_s = options.exit_after_s;
  setup.allow_colors = !options.no_color;

  // The loop wakes 200 times a second: keep the cores out of deep idle while it runs.
  const CpuIdleHold idle_hold(!simulated_time && speed > 0.0 && options.rt != RealtimeMode::kOff, 0,
                              CpuIdleHold::kCpuidleDriverPath, config.device.kind != "sim");
  const ui::ConsoleReport report = ui::run_console(std::move(setup));
  char line[320];
  std::snprintf(line, sizeof line,
                "bellows console: %.1f s, iterations %s%s; valves vented.\n"
                "loop: %llu ticks, missed %llu, latency p50 %.0f p99 %.0f max %.0f us (%s%s); "
                "console: %llu frames (%.1f/s), UI thread CPU %.1f%%\n",
                report.seconds, iteration_range(report.iterations).c_str(),
                report.best_rms_deg >= 0.0
                    ? (", best RMS " + std::to_string(report.best_rms_deg).substr(0, 6) + " deg").c_str()
                    : "",
                static_cast<unsigned long long>(report.ticks), static_cast<unsigned long long>(report.loop.missed),
                report.loop.p50_us, report.loop.p99_us, report.loop.max_us,
                simulated_time ? "simulated clock" : loop.rt_description().c_str(),
                idle_hold.held_us() || idle_hold.spinning_cores() > 0 ? ", cores out of deep idle" : "",
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
  if (report.dropped_events > 0)
    out << "bellows: " << report.dropped_events << " engine events dropped (the event queue was full)\n";
  out << std::flush;
  if (report.stopped_by_signal) return 128 + stop_signal();
  // The operator quit with work the disk did not take (a failed save, confirmed): the environment
  // refused, and a script must not take the run for a saved one.
  if (report.unsaved_work_lost) return 4;
  return 0;
}

}  // namespace bellows
