// One tick of the control scheme (spec section 3), the part every clock and every loop shares:
// PID + feed-forward + ILC correction at the sample rate, set-point mapping, and the two pressure
// controllers at the tick rate. It holds the controller state; the trajectory, the correction and
// the record it writes into are prepared outside the loop, so tick() allocates nothing.
//
// Several joints (../shared/spec/multi-joint.md): each joint has its own PID, its own pair of pressure
// controllers and its own set points, built once for kMaxJoints joints; J of them run. J is what the
// core holds or tracks: the angles given to hold() or the trajectory given to start_trial() (the
// engine passes its trajectory's, so the trajectory is the one place that says how many joints). A
// reading for another joint count than J runs no controller and gets every valve vented (the engine's
// guards fault on such a reading before it gets here). Every joint has the single-joint gains: the
// spec gives no per-joint controller parameters (it names the paper's controllers "per joint"), so
// the [controller] section applies to each joint alike. Joint 1 computes exactly as the single-joint
// core did: with one joint, every number is bit for bit what it was.
//
// Inputs per tick: a SensorReading. Output: the ValveCommand for the coming PWM period.
// Modes: holding fixed angles (between trials) or running a trial (sample k = 0..N).
#pragma once

#include <array>
#include <vector>

#include <Eigen/Dense>

#include "engine/control/device.hpp"
#include "engine/base/parameters.hpp"
#include "engine/control/pid_controller.hpp"
#include "engine/control/pressure_controller.hpp"
#include "engine/trial/setpoints.hpp"
#include "engine/trial/trajectory.hpp"
#include "engine/trial/trial_record.hpp"

namespace bellows {

class ControlCore {
 public:
  /// One joint's controllers between ticks.
  struct JointState {
    PidController::State pid;
    PressureController::State pressure_a, pressure_b;
    ChamberSetpoints setpoints;
    double hold_rad = 0.0;
    double desired_rad = 0.0;
    double u_total_bar = 0.0;
  };
  /// Everything that evolves between ticks while holding: enough to continue a run exactly.
  /// Fixed capacity: joints [0, joint_count) hold the J joints' controllers.
  struct State {
    int tick_in_sample = 0;
    int joint_count = 1;                          // J
    std::array<JointState, kMaxJoints> joints{};  // joints[0] is joint 1
  };

  ControlCore(const ControllerParameters& controller, const TimingParameters& timing);

  /// Hold `angle_rad` with the PID only (no correction) until a trial starts: one joint.
  void hold(double angle_rad);
  /// Hold each joint at its angle: J = angles_rad.size() (1..kMaxJoints). A joint that was not
  /// running before starts with fresh controllers.
  void hold(const JointVector& angles_rad);
  /// Start a trial at the next tick, J = trajectory.joints(). `trajectory`, the correction (N values,
  /// one joint; or N x J, one column per joint) and `record` must outlive the trial; the record is
  /// prepared here for J joints (no allocation when it was prepared so before). A joint beyond the
  /// correction's columns gets none.
  void start_trial(const Trajectory& trajectory, const Eigen::VectorXd& correction_bar, TrialRecord& record);
  void start_trial(const Trajectory& trajectory, const Eigen::MatrixXd& correction_bar, TrialRecord& record);
  /// Abandon a trial in progress; holds the current set points.
  void abort_trial();

  ValveCommand tick(const SensorReading& reading);
  /// A tick without a fresh reading (`last`: the device's last one): no controller runs, every
  /// valve closes (nothing can inflate; the chambers keep their air, so the arm stays near where it
  /// was and control resumes from there), and the trial's clock goes on. A sample that falls on such
  /// a tick is recorded as held (TrialRecord::held): its error is 0, as at k = 0, so that no learning
  /// law learns from it; its inputs and set points are those in force (the previous sample's).
  ValveCommand tick_held(const SensorReading& last);

  /// The joints the core drives (J).
  int joints() const { return joints_; }
  bool trial_running() const { return trajectory_ != nullptr; }
  /// Sample index of the running trial (0..N), or -1 while holding.
  int sample_index() const { return trial_running() ? sample_ : -1; }
  /// Joint `joint`'s (default: joint 1's) set points, total input and desired angle.
  const ChamberSetpoints& setpoints(int joint = 0) const { return loop(joint).setpoints; }
  double last_u_total_bar(int joint = 0) const { return loop(joint).u_total_bar; }
  double desired_angle_rad(int joint = 0) const { return loop(joint).desired_rad; }
  /// Joint 1's PID.
  PidController& pid() { return loops_.front().pid; }
  /// Every joint's PID from scratch (arming).
  void reset_pids();
  /// The same gains for every joint.
  void set_controller_gains(const ControllerParameters& params);
  /// The state between trials. set_state() abandons a trial in progress and holds `hold_rad`.
  State state() const;
  void set_state(const State& state);

 private:
  /// One joint's controllers and set points.
  struct JointLoop {
    PidController pid;
    PressureController pressure_a, pressure_b;
    ChamberSetpoints setpoints;
    double hold_rad = 0.0;
    double desired_rad = 0.0;
    double u_total_bar = 0.0;
    JointState state() const;
    void set_state(const JointState& state);
  };
  JointLoop& loop(int joint) { return loops_[static_cast<std::size_t>(joint)]; }
  const JointLoop& loop(int joint) const { return loops_[static_cast<std::size_t>(joint)]; }
  /// J joints from now on; joints J..kMaxJoints-1 go back to fresh controllers.
  void use_joints(int joints);
  void reset_loop(JointLoop& loop) const;
  void start(const Trajectory& trajectory, const double* correction_bar, Eigen::Index rows, Eigen::Index columns,
             TrialRecord& record);
  ValveCommand step(const SensorReading& reading, bool fresh);
  void run_sample(const SensorReading& reading);
  void hold_sample(const SensorReading& last);
  /// Sample k's end of the trial: the record complete, the trajectory's end held.
  void end_trial_at(int k);
  double correction_bar(int sample, int joint) const;

  ControllerParameters controller_;
  TimingParameters timing_;
  std::vector<JointLoop> loops_;  // kMaxJoints, built once; [0, joints_) run
  int joints_ = 1;
  int tick_in_sample_ = 0;
  int tick_in_trial_ = 0;
  int sample_ = 0;
  const Trajectory* trajectory_ = nullptr;
  const double* correction_ = nullptr;  // column-major, correction_rows_ x correction_columns_
  Eigen::Index correction_rows_ = 0;
  Eigen::Index correction_columns_ = 0;
  TrialRecord* record_ = nullptr;
};

}  // namespace bellows
