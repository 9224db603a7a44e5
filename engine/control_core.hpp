// One tick of the control scheme (spec section 3), the part every clock and every loop shares:
// PID + feed-forward + ILC correction at the sample rate, set-point mapping, and the two pressure
// controllers at the tick rate. It holds the controller state; the trajectory, the correction and
// the record it writes into are prepared outside the loop, so tick() allocates nothing.
//
// Inputs per tick: a SensorReading. Output: the ValveCommand for the coming PWM period.
// Modes: holding a fixed angle (between trials) or running a trial (sample k = 0..N).
#pragma once

#include <Eigen/Dense>

#include "engine/device.hpp"
#include "engine/parameters.hpp"
#include "engine/pid_controller.hpp"
#include "engine/pressure_controller.hpp"
#include "engine/setpoints.hpp"
#include "engine/trajectory.hpp"
#include "engine/trial_record.hpp"

namespace bellows {

class ControlCore {
 public:
  /// Everything that evolves between ticks while holding: enough to continue a run exactly.
  struct State {
    PidController::State pid;
    PressureController::State pressure_a, pressure_b;
    ChamberSetpoints setpoints;
    double hold_rad = 0.0;
    double desired_rad = 0.0;
    double u_total_bar = 0.0;
    int tick_in_sample = 0;
  };

  ControlCore(const ControllerParameters& controller, const TimingParameters& timing);

  /// Hold `angle_rad` with the PID only (no correction) until a trial starts.
  void hold(double angle_rad);
  /// Start a trial at the next tick. `trajectory`, `correction_bar` (N values) and `record`
  /// must outlive the trial; the record is prepared here, before the loop needs it.
  void start_trial(const Trajectory& trajectory, const Eigen::VectorXd& correction_bar, TrialRecord& record);
  /// Abandon a trial in progress; holds the current set point.
  void abort_trial();

  ValveCommand tick(const SensorReading& reading);

  bool trial_running() const { return trajectory_ != nullptr; }
  /// Sample index of the running trial (0..N), or -1 while holding.
  int sample_index() const { return trial_running() ? sample_ : -1; }
  const ChamberSetpoints& setpoints() const { return setpoints_; }
  double last_u_total_bar() const { return u_total_bar_; }
  double desired_angle_rad() const { return desired_rad_; }
  PidController& pid() { return pid_; }
  void set_controller_gains(const ControllerParameters& params);
  /// The state between trials. set_state() abandons a trial in progress and holds `hold_rad`.
  State state() const;
  void set_state(const State& state);

 private:
  void run_sample(const SensorReading& reading);

  ControllerParameters controller_;
  TimingParameters timing_;
  PidController pid_;
  PressureController pressure_a_, pressure_b_;
  ChamberSetpoints setpoints_;
  double hold_rad_ = 0.0;
  double desired_rad_ = 0.0;
  double u_total_bar_ = 0.0;
  int tick_in_sample_ = 0;
  int tick_in_trial_ = 0;
  int sample_ = 0;
  const Trajectory* trajectory_ = nullptr;
  const Eigen::VectorXd* correction_ = nullptr;
  TrialRecord* record_ = nullptr;
};

}  // namespace bellows
