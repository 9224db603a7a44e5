#include "app/run_command.hpp"

#include <cstdio>
#include <ostream>

#include <nlohmann/json.hpp>

#include "app/config_file.hpp"
#include "app/learning_report.hpp"
#include "app/trajectory_file.hpp"
#include "devices/simulated_arm.hpp"
#include "engine/arm_model.hpp"
#include "engine/control_core.hpp"
#include "engine/convergence.hpp"
#include "engine/errors.hpp"
#include "engine/learning_law_factory.hpp"
#include "engine/learning_monitor.hpp"
#include "engine/learning_session.hpp"

namespace bellows {
namespace {

std::string progress_line(const IterationSummary& s) {
  char line[160];
  std::snprintf(line, sizeof line, "iteration %3d  rms %7.3f deg  max error %7.3f deg  max correction %6.4f bar",
                s.iteration, s.rms_deg, s.max_abs_error_deg, s.max_abs_correction_bar);
  return line;
}

}  // namespace

int run_command(const RunOptions& options, std::ostream& out, std::ostream& progress) {
  if (options.iterations < 0) throw InputError("--iterations must not be negative");
  const Configuration config = options.config_path.empty() ? Configuration{} : load_config_file(options.config_path);
  const double sample_s = config.timing.sample_s();
  const Trajectory trajectory = resolve_trajectory(options.trajectory, sample_s, config.trajectory);
  const DiscreteArmModel model = discretize_arm_model(config.model, sample_s);
  const std::unique_ptr<LearningLaw> law = make_learning_law(config, model, trajectory.learning_samples());

  SimulatedArm arm(config.plant, options.seed);
  ControlCore core(config.controller, config.timing);
  LearningSession session(arm, core, *law, trajectory, config.timing, config.controller);
  const ConvergencePrediction prediction = predict_convergence(*law, config, trajectory.learning_samples());
  if (!prediction.warning.empty()) progress << "warning: " << prediction.warning << std::endl;
  LearningMonitor monitor(config.controller.p_max_bar - config.controller.gas.ambient_bar, trajectory.learning_samples());

  nlohmann::json iterations = nlohmann::json::array();
  for (int i = 0; i <= options.iterations; ++i) {
    const IterationSummary s = session.run_trial();
    progress << progress_line(s) << std::endl;
    nlohmann::json iteration = {{"iteration", s.iteration},
                                {"rms_deg", s.rms_deg},
                                {"max_abs_error_deg", s.max_abs_error_deg},
                                {"max_abs_correction_bar", s.max_abs_correction_bar}};
    iteration.update(diagnostics_json(monitor.observe(s.iteration, session.last_record())));
    iterations.push_back(iteration);
    if (i < options.iterations) session.learn();
  }
  if (monitor.windup().detected) {
    progress << "warning: correction wind-up since iteration " << *monitor.windup().first_iteration
             << ": the correction keeps growing where the set points saturate (largest clamped excess "
             << monitor.windup().max_clamped_excess_bar << " bar); law noilc-constrained avoids it" << std::endl;
  }
  if (options.json) {
    const nlohmann::json report = {{"device", arm.name()},
                                   {"trajectory", trajectory.name},
                                   {"law", law->name()},
                                   {"seed", options.seed},
                                   {"samples", trajectory.learning_samples()},
                                   {"prediction", prediction_json(prediction)},
                                   {"windup", windup_json(monitor.windup())},
                                   {"iterations", iterations}};
    out << report.dump() << std::endl;
  }
  return 0;
}

}  // namespace bellows
