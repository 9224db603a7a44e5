#include "engine/operator/learning_session.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

#include "engine/base/errors.hpp"
#include "engine/base/units.hpp"

namespace bellows {
namespace {

// The headless flow sends one command at a time into a queue of hundreds: a refusal means the
// engine stopped taking commands, and the run cannot go on.
void send_or_throw(EngineCore& core, const EngineCommand& command) {
  if (!core.send(command)) {
    throw std::runtime_error(std::string("the engine's command queue is full: ") + to_string(command.kind) +
                             " not sent");
  }
}

}  // namespace

IterationSummary summarize_trial(int iteration, const TrialRecord& record,
                                 const Eigen::Ref<const Eigen::MatrixXd>& correction_bar, double ambient_bar,
                                 double p_max_bar) {
  IterationSummary s;
  s.iteration = iteration;
  s.held_samples = record.held_samples;
  const int joints = record.joint_count();
  s.joint_rms_deg.resize(joints);
  for (int j = 0; j < joints; ++j) s.joint_rms_deg(j) = record.joint_rms_error_deg(j);
  s.max_abs_correction_bar = correction_bar.size() > 0 ? correction_bar.cwiseAbs().maxCoeff() : 0.0;
  const double span = p_max_bar - ambient_bar;
  if (joints == 1) {  // exactly as before joints were counted
    s.rms_deg = record.rms_error_deg();
    s.max_abs_error_deg = record.max_abs_error_deg();
    const Eigen::VectorXd inputs = record.joint_samples(0).u_total_bar.head(record.learning_samples);
    s.saturated_samples = static_cast<int>((inputs.array().abs() > span).count());
    return s;
  }
  // Every joint has N samples: the overall RMS is the RMS of the joints' RMS values.
  s.rms_deg = std::sqrt(s.joint_rms_deg.squaredNorm() / joints);
  const int n = record.learning_samples;
  for (int j = 0; j < joints; ++j) {
    const TrialSamples& joint = record.joint_samples(j);
    if (n > 0)
      s.max_abs_error_deg = std::max(s.max_abs_error_deg, joint.error_rad.tail(n).cwiseAbs().maxCoeff() * kDegPerRad);
    s.saturated_samples += static_cast<int>((joint.u_total_bar.head(n).array().abs() > span).count());
  }
  return s;
}

LearningSession::LearningSession(EngineDriver& driver, LearningLaw& law, Trajectory trajectory,
                                 const TimingParameters& timing, const ControllerParameters& controller)
    : LearningSession(driver, std::make_unique<SingleJointLearning>(law), std::move(trajectory), timing, controller) {}

LearningSession::LearningSession(EngineDriver& driver, std::unique_ptr<SingleJointLearning> single,
                                 Trajectory trajectory, const TimingParameters& timing,
                                 const ControllerParameters& controller)
    : LearningSession(driver, *single, std::move(trajectory), timing, controller) {
  single_ = std::move(single);
}

LearningSession::LearningSession(EngineDriver& driver, JointLearning& learning, Trajectory trajectory,
                                 const TimingParameters& timing, const ControllerParameters& controller)
    : driver_(driver),
      learning_(learning),
      trajectory_(std::move(trajectory)),
      timing_(timing),
      controller_(controller),
      corrections_(Eigen::MatrixXd::Zero(trajectory_.learning_samples(), trajectory_.joints())),
      next_corrections_(trajectory_.learning_samples(), trajectory_.joints()),
      feedback_bar_(trajectory_.learning_samples(), trajectory_.joints()),
      runner_(driver.core(), timing, TrialRunner::Snapshot::kLeaveToOthers) {
  if (learning.samples() != trajectory_.learning_samples()) {
    throw InputError("learning law built for " + std::to_string(learning.samples()) + " samples, trajectory has " +
                     std::to_string(trajectory_.learning_samples()));
  }
  if (learning.joints() != trajectory_.joints()) {
    throw InputError("learning law built for " + std::to_string(learning.joints()) + " joints, trajectory '" +
                     trajectory_.name + "' has " + std::to_string(trajectory_.joints()));
  }
  record_.prepare(trajectory_.learning_samples(), timing_.ticks_per_sample,
                  trajectory_.joints());  // last_record()'s size
  send_or_throw(driver_.core(), EngineCommand::select_trajectory(trajectory_));
}

void LearningSession::set_correction(const Eigen::Ref<const Eigen::MatrixXd>& correction_bar, int iteration) {
  if (correction_bar.rows() != corrections_.rows() || correction_bar.cols() != corrections_.cols()) {
    throw InputError("correction of " + std::to_string(correction_bar.rows()) + " x " +
                     std::to_string(correction_bar.cols()) + " does not match the trajectory's " +
                     std::to_string(corrections_.rows()) + " samples x " + std::to_string(corrections_.cols()) +
                     " joints");
  }
  corrections_ = correction_bar;
  iteration_ = iteration;
}

IterationSummary LearningSession::run_trial() {
  runner_.start(trajectory_, corrections_, record_, TrialRunner::Arming::kIfNeeded);
  const TrialStatus& status = runner_.run_to_completion(driver_, stop_);
  const bool arming = status.command == CommandKind::kArm;
  switch (status.phase) {
    case TrialPhase::kDone:
      break;
    case TrialPhase::kNotSent:
      throw std::runtime_error(status.message);
    case TrialPhase::kRefused:
      throw EngineFault(status.fault,
                        (arming ? "the engine refused to arm: " : "the engine refused the trial: ") + status.message);
    case TrialPhase::kFaulted:
      throw EngineFault(status.fault, "trial aborted: " + status.message);
    case TrialPhase::kCancelled:
      throw EngineFault(FaultCode::kEmergencyStop, "interrupted: valves vented");
    default:
      throw std::logic_error(std::string("LearningSession: the trial ended ") + to_string(status.phase));
  }
  IterationSummary summary =
      summarize_trial(iteration_, record_, corrections_, controller_.gas.ambient_bar, controller_.p_max_bar);
  history_.push_back(summary);
  return summary;
}

void LearningSession::learn() {
  const int n = record_.learning_samples;
  for (int j = 0; j < record_.joint_count(); ++j) feedback_bar_.col(j) = record_.joint_samples(j).u_pid_bar.head(n);
  learning_.set_input_context(feedback_bar_, controller_.p_max_bar - controller_.gas.ambient_bar);
  learning_.set_held_outputs(record_.held);
  learning_.update(corrections_, record_.normalized_joint_errors(), next_corrections_);
  corrections_.swap(next_corrections_);
  ++iteration_;
}

}  // namespace bellows
