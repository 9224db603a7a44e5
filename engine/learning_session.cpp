#include "engine/learning_session.hpp"

#include <cmath>
#include <string>

#include "engine/errors.hpp"

namespace bellows {

IterationSummary summarize_trial(int iteration, const TrialRecord& record, const Eigen::VectorXd& correction_bar,
                                 double ambient_bar, double p_max_bar) {
  IterationSummary s;
  s.iteration = iteration;
  s.rms_deg = record.rms_error_deg();
  s.max_abs_error_deg = record.max_abs_error_deg();
  s.max_abs_correction_bar = correction_bar.size() > 0 ? correction_bar.cwiseAbs().maxCoeff() : 0.0;
  const double span = p_max_bar - ambient_bar;
  const Eigen::VectorXd inputs = record.samples.u_total_bar.head(record.learning_samples);
  s.saturated_samples = static_cast<int>((inputs.array().abs() > span).count());
  return s;
}

void run_ticks_simulated(Device& device, ControlCore& core, long ticks, double tick_s) {
  for (long i = 0; i < ticks; ++i) {
    device.write_valves(core.tick(device.read_sensors()));
    device.advance(tick_s);
  }
}

LearningSession::LearningSession(Device& device, ControlCore& core, LearningLaw& law, Trajectory trajectory,
                                 const TimingParameters& timing, const ControllerParameters& controller)
    : device_(device),
      core_(core),
      law_(law),
      trajectory_(std::move(trajectory)),
      timing_(timing),
      controller_(controller),
      correction_(Eigen::VectorXd::Zero(trajectory_.learning_samples())),
      next_correction_(trajectory_.learning_samples()) {
  if (law.samples() != trajectory_.learning_samples()) {
    throw InputError("learning law built for " + std::to_string(law.samples()) + " samples, trajectory has " +
                     std::to_string(trajectory_.learning_samples()));
  }
}

void LearningSession::set_correction(const Eigen::VectorXd& correction_bar, int iteration) {
  if (correction_bar.size() != correction_.size()) throw InputError("correction length does not match the trajectory");
  correction_ = correction_bar;
  iteration_ = iteration;
}

IterationSummary LearningSession::run_trial() {
  core_.hold(trajectory_.angle_rad(0));
  run_ticks_simulated(device_, core_, std::lround(timing_.settle_s / timing_.tick_s), timing_.tick_s);
  core_.start_trial(trajectory_, correction_, record_);
  while (!record_.complete) run_ticks_simulated(device_, core_, 1, timing_.tick_s);
  IterationSummary summary =
      summarize_trial(iteration_, record_, correction_, controller_.gas.ambient_bar, controller_.p_max_bar);
  history_.push_back(summary);
  return summary;
}

void LearningSession::learn() {
  law_.set_input_context(record_.samples.u_pid_bar.head(record_.learning_samples),
                         controller_.p_max_bar - controller_.gas.ambient_bar);
  law_.update(correction_, record_.normalized_error(), next_correction_);
  correction_.swap(next_correction_);
  ++iteration_;
}

}  // namespace bellows
