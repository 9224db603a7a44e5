#include "app/run_command.hpp"

#include <cstdio>
#include <memory>
#include <optional>
#include <ostream>
#include <sstream>

#include <nlohmann/json.hpp>

#include "app/config_file.hpp"
#include "app/cpu_idle_hold.hpp"
#include "app/lcm_url.hpp"
#include "app/rig_profile_file.hpp"
#include "app/learning_model.hpp"
#include "app/learning_report.hpp"
#include "app/run_io.hpp"
#include "app/run_progress.hpp"
#include "app/run_recording.hpp"
#include "app/signals.hpp"
#include "app/trajectory_file.hpp"
#include "app/transfer_sources.hpp"
#include "engine/model/arm_chain_parameters.hpp"
#include "engine/model/arm_model.hpp"
#include "engine/config/convergence.hpp"
#include "engine/config/joint_convergence.hpp"
#include "engine/rt/engine_core.hpp"
#include "engine/base/errors.hpp"
#include "engine/config/joint_learning_factory.hpp"
#include "engine/config/learning_law_factory.hpp"
#include "engine/learning/learning_monitor.hpp"
#include "engine/operator/learning_session.hpp"
#include "sessions/session_store.hpp"
#include "ui/learning_text.hpp"

namespace bellows {
namespace {

nlohmann::json to_json(const IterationSummary& s) {
  return {
      {"iteration", s.iteration},
      {"rms_deg", s.rms_deg},
      {"joint_rms_deg", std::vector<double>(s.joint_rms_deg.data(), s.joint_rms_deg.data() + s.joint_rms_deg.size())},
      {"max_abs_error_deg", s.max_abs_error_deg},
      {"max_abs_correction_bar", s.max_abs_correction_bar},
      {"saturated_samples", s.saturated_samples},
      {"held_samples", s.held_samples}};
}

/// The session's event for a trial that rode through missing readings: which samples were held
/// (their error is 0 and nothing is learned from them; the iteration's files are unchanged).
std::string held_samples_line(const IterationSummary& s, const TrialRecord& record) {
  std::string line = "iteration " + std::to_string(s.iteration) + ": " + std::to_string(s.held_samples) +
                     " samples held (no fresh reading; error 0, not learned from): k =";
  int listed = 0;
  for (std::size_t k = 0; k < record.held.size(); ++k) {
    if (record.held[k] == 0) continue;
    if (++listed > 50) return line + " ...";
    // Not `" " + std::to_string(k)`: GCC 12 warns falsely on it in some unity batches (its bugs 105329, 105651).
    line += ' ';
    line += std::to_string(k);
  }
  return line;
}

/// --transfer-from: the first correction learned from saved sessions (before anything starts, so that
/// a session that does not fit is refused with nothing created).
std::optional<TransferReport> transfer_for(const RunOptions& options, const Configuration& config,
                                           const Trajectory& trajectory, bool resuming) {
  if (options.transfer_from.empty()) return std::nullopt;
  if (resuming) throw InputError("--transfer-from gives a new session its first correction; a resumed session has one");
  const TransferMethod method = parse_transfer_method(options.transfer_method);
  std::filesystem::path data_dir;
  try {
    data_dir = options.data_dir.empty() ? default_data_dir() : std::filesystem::path(options.data_dir);
  } catch (const InputError&) {
    // Without a data directory the sources must be paths; resolve_session_dir() says so.
  }
  const DeviceParameters device = resolve_device(options.device, config.device);
  const std::string rig_profile = device.kind == "t7" ? rig_profile_or_default(device.rig_profile).name : std::string();
  const std::vector<Session> sessions =
      load_transfer_sessions(options.transfer_from, data_dir, config, device.kind, rig_profile);
  return compute_transfer(sessions, config, trajectory, method);
}

/// --trajectory, or without it the paper's trajectory for the arm's joints (paper, paper2, paper3).
std::string trajectory_name(const RunOptions& options, const ArmParameters& arm) {
  if (options.trajectory_given || !arm.has_chain()) return options.trajectory;
  return "paper" + std::to_string(arm_joint_count(arm));
}

}  // namespace

std::string resolve_clock(const std::string& given, const std::string& device_kind) {
  if (!given.empty() && given != "sim" && given != "wall" && given != "lockstep")
    throw InputError("--clock must be sim, wall or lockstep");
  const bool rig = device_kind != "sim";
  if (given == "lockstep" && device_kind != "lcm") {
    throw InputError(
        "--clock lockstep waits for an LCM rig's answers (a stepped simulator, io-sim --stepped): it needs --device "
        "lcm, not " +
        device_kind);
  }
  if (rig && given == "sim") {
    throw InputError(
        "--clock sim cannot drive --device " + device_kind +
        ": a real rig's time passes on its own (a rig runs on the wall clock; leave --clock out, or --clock lockstep "
        "against a stepped simulator, io-sim --stepped)");
  }
  if (!given.empty()) return given;
  return rig ? "wall" : "sim";
}

double parse_speed(const std::string& speed) {
  if (speed == "max") return 0.0;
  for (const char* allowed : {"1", "2", "5", "10"}) {
    if (speed == allowed) return std::stod(speed);
  }
  throw InputError("--speed must be 1, 2, 5, 10 or max, not '" + speed + "'");
}

int run_command(const RunOptions& given_options, std::ostream& out, std::ostream& progress) {
  if (given_options.iterations < 0) throw InputError("--iterations must not be negative");
  if (!given_options.clock.empty() && given_options.clock != "lockstep")
    resolve_clock(given_options.clock, "sim");  // a bad word before anything is read
  if (!given_options.lcm_url.empty()) check_lcm_url(given_options.lcm_url, "--lcm");  // before a session exists
  const double speed = parse_speed(given_options.speed);
  RunRecording recording(given_options);  // with --resume: the saved configuration, trajectory and state
  const Session* resumed = recording.resuming() ? &recording.resumed() : nullptr;
  Configuration config = resumed != nullptr                  ? resumed->manifest.configuration
                         : given_options.config_path.empty() ? Configuration{}
                                                             : load_config_file(given_options.config_path);
  const DeviceParameters device_wanted = resolve_device(given_options.device, config.device);
  RunOptions options = given_options;  // with the clock the device decides when --clock was left out
  options.clock = resolve_clock(given_options.clock, device_wanted.kind);
  // The model the learning uses: the rig profile's identified one, if it has one (a resumed session:
  // the one it recorded). The session's configuration records it.
  LearningModel learning_model;
  if (resumed != nullptr) {
    learning_model.model = config.model;
    if (!resumed->manifest.model_source.empty()) learning_model.source = resumed->manifest.model_source;
  } else {
    learning_model = choose_learning_model(config, device_wanted);
  }
  config.model = learning_model.model;
  if (options.speed_given && options.clock != "wall") {  // never ignored in silence
    throw InputError("--speed is for --clock wall: the simulated clock runs as fast as it can");
  }
  const double sample_s = config.timing.sample_s();
  const Trajectory trajectory =
      resumed != nullptr ? resumed->trajectory
                         : resolve_trajectory(trajectory_name(options, config.arm), sample_s, config.trajectory);
  require_driven_joints(trajectory, config.arm);
  const std::uint64_t seed = resumed != nullptr ? recording.resumed_seed() : options.seed;
  const DiscreteArmModel model = discretize_arm_model(config.model, sample_s);
  const std::unique_ptr<JointLearning> law =
      make_joint_learning(config, model, trajectory.joints(), trajectory.learning_samples());
  const std::optional<TransferReport> transfer = transfer_for(options, config, trajectory, resumed != nullptr);

  RunIo io(options, speed, seed, config);  // the simulated arm, or a rig over LCM
  Device& device = io.device();
  SimulatedArm* arm = io.simulated_arm();
  EngineCore core(device, config.controller, config.timing, config.safety);
  const StopSignalTarget stop_target(core);  // SIGINT/SIGTERM/SIGHUP/SIGQUIT latch the emergency stop at once
  io.add_telemetry_tap(core);
  const RunIo::StopOnExit stop_io(io);  // before `core` (and its telemetry tap) goes
  std::unique_ptr<EngineDriver> driver;
  SimulatedClock* clock = nullptr;
  RealtimeLoop* loop = nullptr;
  if (options.clock == "sim" || options.clock == "lockstep") {  // lockstep: the engine's time follows the rig's answers
    auto simulated = io.simulated_clock(core);
    clock = simulated.get();
    driver = std::move(simulated);
  } else {
    auto realtime = std::make_unique<RealtimeLoop>(core, device, speed);
    loop = realtime.get();
    driver = std::move(realtime);
  }
  LearningSession session(*driver, *law, trajectory, config.timing, config.controller);
  session.set_stop_flag(&stop_requested());
  SimulatedArmChain* chain = io.simulated_arm_chain();                   // the simulated arm of several joints, or null
  if (chain != nullptr) recording.restore(chain, core, clock, session);  // before the first tick
  else recording.restore(arm, core, clock, session);
  Configuration recorded = config;  // the device as opened, whatever [device] said
  recorded.device = io.device_parameters();
  if (transfer) session.set_correction(transfer->result.correction_bar, 0);  // zero when it fell back
  recording.start(recorded, trajectory, device.name(), seed, options.iterations, io.opened().session_info(),
                  learning_model.source,
                  transfer ? nlohmann::ordered_json::parse(transfer_json(*transfer).dump()) : nlohmann::ordered_json());
  const int trials = recording.trials(options.iterations);
  const int first_iteration = resumed != nullptr ? static_cast<int>(resumed->iterations.size()) : 0;
  RunProgressReport said(progress, choose_progress_style(options.verbose, options.quiet, options.progress_on_terminal),
                         first_iteration, first_iteration + trials - 1);
  if (const std::string line = learning_model_line(learning_model); !line.empty()) said.note(line);
  if (transfer) said.note(transfer_line(*transfer));
  if (!recording.directory().empty()) said.note("session " + recording.directory().string());
  io.start_telemetry(recording.directory());     // its LCM log goes into the session
  ConvergencePrediction prediction;              // one joint
  JointConvergencePrediction joints_prediction;  // several: the arm's and each joint's
  try {
    if (const LearningLaw* single = law->single_joint_law(); single != nullptr) {
      prediction = predict_convergence(*single, config, trajectory.learning_samples(), &stop_requested());
    } else {
      joints_prediction =
          predict_joint_convergence(config, trajectory.joints(), trajectory.learning_samples(), &stop_requested());
      for (const std::string& line : ui::joint_prediction_lines(joints_prediction, config.ilc.law)) said.note(line);
    }
  } catch (const Cancelled&) {
    // Stopped by a signal: the first trial sees the flag too, vents and records why.
  }
  if (!prediction.warning.empty()) said.note("warning: " + prediction.warning);
  LearningMonitor monitor(config.controller.p_max_bar - config.controller.gas.ambient_bar,
                          trajectory.learning_samples(), trajectory.joints());
  if (resumed != nullptr) {  // the saved iterations too: wind-up may span a resume
    for (std::size_t i = 0; i < resumed->iterations.size(); ++i) {
      monitor.observe(static_cast<int>(i), resumed->iterations[i].record);
    }
  }
  // Paced wall-clock ticks wake from idle 200 times a second: keep the cores out of deep idle (for a
  // rig, where no cpuidle driver would act on it, by spinning: app/cpu_idle_hold.hpp).
  const CpuIdleHold idle_hold(loop != nullptr && speed > 0.0 && options.rt != RealtimeMode::kOff, 0,
                              CpuIdleHold::kCpuidleDriverPath, io.device_parameters().kind != "sim");
  if (loop != nullptr) loop->start(options.rt);

  nlohmann::json iterations = nlohmann::json::array();
  int status = 0;
  std::string failure;
  std::string failure_name;
  try {
    if (std::string why = io.wait_for_rig(stop_requested(), options.clock == "lockstep" ? clock : nullptr);
        !why.empty()) {
      failure = std::move(why);
      failure_name = fault_name(FaultCode::kRigUnavailable);
      status = stop_signal() != 0 ? 128 + stop_signal() : kExitEnvironment;  // the rig, not a fault
      said.error("bellows: " + failure);
      recording.fault(failure);
    }
    said.begin_trials();
    for (int i = 0; failure.empty() && i < trials; ++i) {
      IterationSummary s = session.run_trial();
      if (s.iteration > 0) s.learned_with = learned_with(config);  // iteration 0 applies what it was given
      io.post_trial(s, session.correction_bar());                  // the correction this trial applied
      session.learn();  // also after the last trial: the saved session resumes with this correction
      if (const std::string note = session.learning().take_note(); !note.empty()) recording.note("model-refit", note);
      // On disk before the line says it is done.
      if (chain != nullptr) recording.save(session, s, chain, core, clock);
      else recording.save(session, s, arm, core, clock);
      if (s.held_samples > 0) recording.note("held-samples", held_samples_line(s, session.last_record()));
      said.iteration(s);
      nlohmann::json iteration = to_json(s);
      iteration.update(diagnostics_json(monitor.observe(s.iteration, session.last_record())));
      iterations.push_back(iteration);
    }
  } catch (const EngineFault& fault) {
    const bool interrupted = fault.code() == FaultCode::kEmergencyStop && stop_signal() != 0;
    failure = interrupted ? std::string("interrupted by ") + stop_signal_name() + ": valves vented" : fault.what();
    failure_name = fault_name(core.fault());
    if (std::string why = io.explain_fault(fault.code()); !why.empty()) failure = std::move(why);
    status = interrupted ? 128 + stop_signal() : kExitFault;
    said.error("bellows: " + failure + " (" + fault_name(fault.code()) + ")");
    recording.fault(failure + " (" + fault_name(fault.code()) + ")", core);
  } catch (const std::exception& error) {
    said.finish();                      // main() says what went wrong on a line of its own
    if (loop != nullptr) loop->stop();  // vents
    else device.vent();
    recording.fault(error.what());
    throw;
  }
  if (loop != nullptr) loop->stop();  // vents
  else device.vent();
  const std::string log_error = io.finish_log();  // the rig's last vent command, the rest of the telemetry, the log
  said.finish();
  if (!log_error.empty()) said.error("bellows: " + log_error);
  if (const std::string warning = io.warning(); !warning.empty()) said.error("bellows: " + warning);  // a loss
  if (trajectory.joints() > 1) {  // every joint's, wound up or not
    for (const std::string& line :
         ui::windup_monitor_lines(monitor.windup(), static_cast<int>(monitor.history().size())))
      said.note(line);
  } else if (monitor.windup().detected) {
    std::ostringstream warning;
    warning << "warning: correction wind-up since iteration " << *monitor.windup().first_iteration
            << ": the correction keeps growing where the set points saturate (largest clamped excess "
            << monitor.windup().max_clamped_excess_bar << " bar); law " << ui::kWindupRemedyLaw << " avoids it";
    said.note(warning.str());
  }
  if (core.dropped_events() > 0) {  // a loss like any other: said, and kept with the session
    said.error("bellows: " + std::to_string(core.dropped_events()) +
               " engine events dropped (the event queue was full)");
    recording.note("dropped-events",
                   std::to_string(core.dropped_events()) + " engine events dropped (the event queue was full)");
  }
  if (core.missed_deadline_warnings() > 0) {
    said.note("bellows: " + std::to_string(core.missed_deadline_warnings()) +
              " deadlines missed (a warning: the simulated arm's time follows the engine's ticks)");
  }
  if (status == 0) recording.finish(trials);
  if (!log_error.empty() && status == 0) status = kExitEnvironment;  // the session is whole; the log is not there

  if (options.json) {
    nlohmann::json report = {
        {"device", device.name()},
        {"rig_profile", io.opened().rig_profile_name()},
        {"trajectory", trajectory.name},
        {"law", law->name()},
        {"joints", trajectory.joints()},
        {"model", learning_model_json(learning_model)},
        {"seed", seed},
        {"clock", options.clock},
        {"samples", trajectory.learning_samples()},
        {"prediction",
         trajectory.joints() > 1 ? joint_prediction_json(joints_prediction) : prediction_json(prediction)},
        {"windup", windup_json(monitor.windup())},
        {"session",
         recording.directory().empty() ? nlohmann::json(nullptr) : nlohmann::json(recording.directory().string())},
        {"iterations", iterations}};
    if (trajectory.joints() > 1) report["arm"] = {{"name", config.arm.name()}, {"joint_model", config.ilc.joint_model}};
    if (transfer) report["transfer"] = transfer_json(*transfer);
    if (!failure.empty()) report["fault"] = {{"name", failure_name}, {"message", failure}};
    report["dropped_events"] = core.dropped_events();
    report["dropped_telemetry"] = core.dropped_telemetry();
    if (const nlohmann::json lcm = io.report(); !lcm.is_null()) report["lcm"] = lcm;
    if (io.device_parameters().kind == "t7") report["t7"] = io.opened().report();  // late answers and readings
    if (loop != nullptr) {
      const LatencySummary l = loop->latency();
      report["loop"] = {
          {"ticks", core.ticks()},
          {"missed", l.missed},
          {"missed_warnings", core.missed_deadline_warnings()},
          {"held_ticks", core.held_ticks()},
          {"latency_us", {{"p50", l.p50_us}, {"p99", l.p99_us}, {"max", l.max_us}}},
          {"rt", loop->rt_description()},
          {"cpu_wakeup_limit_us", idle_hold.held_us() ? nlohmann::json(*idle_hold.held_us()) : nlohmann::json(nullptr)},
          {"cpu_idle_not_held", idle_hold.why_not()},
          {"cpu_idle_spinning_cores", idle_hold.spinning_cores()},
          {"speed", options.speed}};
      if (const DeviceHealth h = device.health(); h.has_link) {  // the link's figures, e.g. the T7's Modbus round trip
        report["loop"]["link"] = {
            {"round_trip_ms",
             {{"p50", h.round_trip_p50_ms}, {"p99", h.round_trip_p99_ms}, {"max", h.round_trip_max_ms}}},
            {"exchanges", h.exchanges},
            {"errors", h.link_errors},
            {"stale_readings", h.stale_readings}};
      }
    }
    out << report.dump(-1, ' ', true, nlohmann::json::error_handler_t::replace)
        << std::endl;  // no raw text on a terminal
  }
  return status;
}

}  // namespace bellows
