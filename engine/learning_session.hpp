// Trials and learning between them, driven through the engine like any operator would: arm, start
// a trial (the engine settles at the trajectory's start, then runs it with the current correction),
// wait for the record, hand it to the learning law for the next correction. The same code runs on
// a simulated clock (headless, deterministic) and on the real-time loop (wall time).
#pragma once

#include <atomic>
#include <stdexcept>
#include <vector>

#include "engine/engine_driver.hpp"
#include "engine/errors.hpp"
#include "engine/learning_law.hpp"
#include "engine/trajectory.hpp"
#include "engine/trial_record.hpp"

namespace bellows {

/// What one iteration achieved, as the run reports it.
struct IterationSummary {
  int iteration = 0;
  double rms_deg = 0.0;
  double max_abs_error_deg = 0.0;
  double max_abs_correction_bar = 0.0;  // of the correction applied in this trial
  int saturated_samples = 0;            // samples whose total input was clamped
};

IterationSummary summarize_trial(int iteration, const TrialRecord& record, const Eigen::VectorXd& correction_bar,
                                 double ambient_bar, double p_max_bar);

/// The engine faulted (or refused) while the session was running a trial. Carries the fault code.
class EngineFault : public FaultError {  // exit status 3
 public:
  EngineFault(FaultCode code, const std::string& message) : FaultError(message), code_(code) {}
  FaultCode code() const { return code_; }

 private:
  FaultCode code_;
};

class LearningSession {
 public:
  LearningSession(EngineDriver& driver, LearningLaw& law, Trajectory trajectory, const TimingParameters& timing,
                  const ControllerParameters& controller);

  /// Arms if needed, runs one trial with the current correction and records it. Throws EngineFault
  /// if the engine faults or refuses; the trial is then not counted.
  IterationSummary run_trial();
  /// Replaces the correction by the law's update from the last trial.
  void learn();

  int iteration() const { return iteration_; }
  const Trajectory& trajectory() const { return trajectory_; }
  const Eigen::VectorXd& correction_bar() const { return correction_; }
  void set_correction(const Eigen::VectorXd& correction_bar, int iteration);
  const TrialRecord& last_record() const { return record_; }
  const std::vector<IterationSummary>& history() const { return history_; }
  void set_history(std::vector<IterationSummary> history) { history_ = std::move(history); }
  LearningLaw& law() { return law_; }
  /// While waiting for the engine, a set flag (a signal arrived) stops the engine at once (vents)
  /// and makes run_trial() throw EngineFault(kEmergencyStop).
  void set_stop_flag(const std::atomic<bool>* stop) { stop_ = stop; }

 private:
  void ensure_armed();
  /// Waits for the next event, letting engine time pass.
  EngineEvent next_event();

  EngineDriver& driver_;
  LearningLaw& law_;
  Trajectory trajectory_;
  TimingParameters timing_;
  ControllerParameters controller_;
  Eigen::VectorXd correction_;
  Eigen::VectorXd next_correction_;
  TrialRecord record_;
  int iteration_ = 0;
  std::uint32_t next_trial_id_ = 1;
  std::vector<IterationSummary> history_;
  const std::atomic<bool>* stop_ = nullptr;
};

}  // namespace bellows
