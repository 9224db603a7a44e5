#include "app/run_command.hpp"

#include <cstdio>
#include <ostream>

#include <nlohmann/json.hpp>

#include "app/config_file.hpp"
#include "app/run_recording.hpp"
#include "app/trajectory_file.hpp"
#include "devices/simulated_arm.hpp"
#include "engine/arm_model.hpp"
#include "engine/control_core.hpp"
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

}  // namespace

int run_command(const RunOptions& options, std::ostream& out, std::ostream& progress) {
  if (options.iterations < 0) throw InputError("--iterations must not be negative");
  RunRecording recording(options);  // with --resume: the saved configuration, trajectory and state
  const SessionManifest* resumed = recording.resuming() ? &recording.resumed().manifest : nullptr;
  const Configuration config = resumed != nullptr          ? resumed->configuration
                               : options.config_path.empty() ? Configuration{}
                                                             : load_config_file(options.config_path);
  const double sample_s = config.timing.sample_s();
  const Trajectory trajectory = resumed != nullptr ? recording.resumed().trajectory
                                                   : resolve_trajectory(options.trajectory, sample_s, config.trajectory);
  const std::uint64_t seed = recording.resuming() ? recording.resumed_seed() : options.seed;
  const DiscreteArmModel model = discretize_arm_model(config.model, sample_s);
  const std::unique_ptr<LearningLaw> law = make_learning_law(config, model, trajectory.learning_samples());

  SimulatedArm arm(config.plant, seed);
  ControlCore core(config.controller, config.timing);
  LearningSession session(arm, core, *law, trajectory, config.timing, config.controller);
  recording.restore(arm, core, session);
  recording.start(config, trajectory, arm.name(), seed, options.iterations);
  if (!recording.directory().empty()) progress << "session " << recording.directory().string() << std::endl;

  nlohmann::json iterations = nlohmann::json::array();
  const int trials = recording.trials(options.iterations);
  try {
    for (int i = 0; i < trials; ++i) {
      const IterationSummary s = session.run_trial();
      session.learn();  // also after the last trial: the saved session resumes with this correction
      recording.save(session, s, arm, core);  // on disk before the line says it is done
      progress << progress_line(s) << std::endl;
      iterations.push_back({{"iteration", s.iteration},
                            {"rms_deg", s.rms_deg},
                            {"max_abs_error_deg", s.max_abs_error_deg},
                            {"max_abs_correction_bar", s.max_abs_correction_bar},
                            {"saturated_samples", s.saturated_samples}});
    }
  } catch (const std::exception& error) {
    recording.fault(error.what());
    throw;
  }
  recording.finish(trials);
  if (options.json) {
    const nlohmann::json report = {{"device", arm.name()},
                                   {"trajectory", trajectory.name},
                                   {"law", law->name()},
                                   {"seed", seed},
                                   {"samples", trajectory.learning_samples()},
                                   {"session", recording.directory().empty() ? nlohmann::json(nullptr)
                                                                             : nlohmann::json(recording.directory().string())},
                                   {"iterations", iterations}};
    out << report.dump() << std::endl;
  }
  return 0;
}

}  // namespace bellows
