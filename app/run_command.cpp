#include "app/run_command.hpp"

#include <cstdio>
#include <memory>
#include <ostream>

#include <nlohmann/json.hpp>

#include "app/config_file.hpp"
#include "app/run_io.hpp"
#include "app/signals.hpp"
#include "app/trajectory_file.hpp"
#include "engine/arm_model.hpp"
#include "engine/engine_core.hpp"
#include "engine/errors.hpp"
#include "engine/learning_law_factory.hpp"
#include "engine/learning_session.hpp"

namespace bellows {
namespace {

std::string progress_line(const IterationSummary& s) {
  char line[160];
  std::snprintf(line, sizeof line, "iteration %3d  rms %7.3f deg  max error %7.3f deg  max correction %6.4f bar",
                s.iteration, s.rms_deg, s.max_abs_error_deg, s.max_abs_correction_bar);
  return line;
}

nlohmann::json to_json(const IterationSummary& s) {
  return {{"iteration", s.iteration},
          {"rms_deg", s.rms_deg},
          {"max_abs_error_deg", s.max_abs_error_deg},
          {"max_abs_correction_bar", s.max_abs_correction_bar},
          {"saturated_samples", s.saturated_samples}};
}

}  // namespace

double parse_speed(const std::string& speed) {
  if (speed == "max") return 0.0;
  for (const char* allowed : {"1", "2", "5", "10"}) {
    if (speed == allowed) return std::stod(speed);
  }
  throw InputError("--speed must be 1, 2, 5, 10 or max, not '" + speed + "'");
}

int run_command(const RunOptions& options, std::ostream& out, std::ostream& progress) {
  if (options.iterations < 0) throw InputError("--iterations must not be negative");
  if (options.clock != "sim" && options.clock != "wall") throw InputError("--clock must be sim or wall");
  const double speed = parse_speed(options.speed);
  const Configuration config = options.config_path.empty() ? Configuration{} : load_config_file(options.config_path);
  const double sample_s = config.timing.sample_s();
  const Trajectory trajectory = resolve_trajectory(options.trajectory, sample_s, config.trajectory);
  const DiscreteArmModel model = discretize_arm_model(config.model, sample_s);
  const std::unique_ptr<LearningLaw> law = make_learning_law(config, model, trajectory.learning_samples());

  RunIo io({options.device, options.lcm_url, options.lcm_log, options.clock, speed, options.seed, options.rt}, config);
  Device& device = io.device();
  EngineCore core(device, config.controller, config.timing, config.safety);
  io.start_telemetry(core);
  const RunIo::StopOnExit stop_io(io);  // before `core` (and its telemetry tap) goes
  std::unique_ptr<EngineDriver> driver;
  RealtimeLoop* loop = nullptr;
  if (options.clock == "sim") {
    driver = io.simulated_clock(core);
  } else {
    auto realtime = std::make_unique<RealtimeLoop>(core, device, speed);
    loop = realtime.get();
    driver = std::move(realtime);
    loop->start(options.rt);
  }
  LearningSession session(*driver, *law, trajectory, config.timing, config.controller);
  session.set_stop_flag(&stop_requested());

  nlohmann::json iterations = nlohmann::json::array();
  int status = 0;
  std::string failure;
  std::string failure_name;
  try {
    if (std::string why = io.wait_for_rig(stop_requested()); !why.empty()) {
      failure = std::move(why);
      failure_name = "rig-unavailable";
      status = stop_signal() != 0 ? 128 + stop_signal() : 3;
      progress << "bellows: " << failure << std::endl;
    }
    for (int i = 0; failure.empty() && i <= options.iterations; ++i) {
      const IterationSummary s = session.run_trial();
      io.post_trial(s, session.correction_bar());
      progress << progress_line(s) << std::endl;
      iterations.push_back(to_json(s));
      if (i < options.iterations) session.learn();
    }
  } catch (const EngineFault& fault) {
    failure = fault.what();
    failure_name = fault_name(core.fault());
    status = fault.code() == FaultCode::kEmergencyStop && stop_signal() != 0 ? 128 + stop_signal() : 3;
    progress << "bellows: " << failure << " (" << fault_name(fault.code()) << ")" << std::endl;
  }
  if (loop != nullptr) loop->stop();  // vents
  else device.vent();
  io.stop();  // the rig's last vent command, the rest of the telemetry
  if (const std::string warning = io.warning(); !warning.empty()) progress << "bellows: " << warning << std::endl;

  if (options.json) {
    nlohmann::json report = {{"device", device.name()},
                             {"trajectory", trajectory.name},
                             {"law", law->name()},
                             {"seed", options.seed},
                             {"clock", options.clock},
                             {"samples", trajectory.learning_samples()},
                             {"iterations", iterations}};
    if (!failure.empty()) report["fault"] = {{"name", failure_name}, {"message", failure}};
    if (const nlohmann::json lcm = io.report(); !lcm.is_null()) report["lcm"] = lcm;
    if (loop != nullptr) {
      const LatencySummary l = loop->latency();
      report["loop"] = {{"ticks", core.ticks()},
                        {"missed", l.missed},
                        {"latency_us", {{"p50", l.p50_us}, {"p99", l.p99_us}, {"max", l.max_us}}},
                        {"rt", loop->rt_description()},
                        {"speed", options.speed}};
    }
    out << report.dump() << std::endl;
  }
  return status;
}

}  // namespace bellows
