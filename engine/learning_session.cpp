#include "engine/learning_session.hpp"

#include <cmath>
#include <string>

#include "engine/errors.hpp"

namespace bellows {
namespace {

// The headless flow sends one command at a time into a queue of hundreds: a refusal means the
// engine stopped taking commands, and the run cannot go on.
void send_or_throw(EngineCore& core, const EngineCommand& command) {
  if (!core.send(command)) {
    throw std::runtime_error(std::string("the engine's command queue is full: ") + to_string(command.kind) + " not sent");
  }
}

}  // namespace

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

LearningSession::LearningSession(EngineDriver& driver, LearningLaw& law, Trajectory trajectory,
                                 const TimingParameters& timing, const ControllerParameters& controller)
    : driver_(driver),
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
  record_.prepare(trajectory_.learning_samples(), timing_.ticks_per_sample);
  send_or_throw(driver_.core(), EngineCommand::select_trajectory(trajectory_));
}

void LearningSession::set_correction(const Eigen::VectorXd& correction_bar, int iteration) {
  if (correction_bar.size() != correction_.size()) throw InputError("correction length does not match the trajectory");
  correction_ = correction_bar;
  iteration_ = iteration;
}

EngineEvent LearningSession::next_event() {
  EngineEvent event;
  while (!driver_.core().poll_event(event)) {
    if (stop_ != nullptr && stop_->load(std::memory_order_relaxed)) {
      driver_.core().request_emergency_stop();  // a latch: the next tick vents, whatever is queued
      while (driver_.core().state() != EngineState::kFault) driver_.await();
      throw EngineFault(FaultCode::kEmergencyStop, "interrupted: valves vented");
    }
    driver_.await();
  }
  return event;
}

void LearningSession::ensure_armed() {
  EngineCore& core = driver_.core();
  if (core.state() == EngineState::kArmed) return;
  send_or_throw(core, EngineCommand::of(CommandKind::kArm));
  for (;;) {
    const EngineEvent event = next_event();
    if (event.kind == EventKind::kStateChanged && event.to == EngineState::kArmed) return;
    if (event.kind == EventKind::kCommandRefused) {
      throw EngineFault(core.fault(), std::string("the engine refused to arm: ") + event.refusal);
    }
    if (event.kind == EventKind::kFault) throw EngineFault(event.fault, fault_message(event.fault));
  }
}

IterationSummary LearningSession::run_trial() {
  ensure_armed();
  const EngineCommand start = EngineCommand::start_trial(
      trajectory_, correction_, record_, static_cast<int>(std::lround(timing_.settle_s / timing_.tick_s)), next_trial_id_++);
  send_or_throw(driver_.core(), start);
  for (;;) {
    const EngineEvent event = next_event();
    if (event.kind == EventKind::kTrialComplete && event.trial_id == start.trial_id) break;
    if (event.kind == EventKind::kTrialAborted && event.trial_id == start.trial_id) {
      const FaultCode code = driver_.core().fault();
      throw EngineFault(code, std::string("trial aborted: ") + fault_message(code));
    }
    if (event.kind == EventKind::kCommandRefused) {
      throw EngineFault(driver_.core().fault(), std::string("the engine refused the trial: ") + event.refusal);
    }
  }
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
