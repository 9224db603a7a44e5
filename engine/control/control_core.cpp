#include "engine/control/control_core.hpp"

#include <algorithm>
#include <numbers>

namespace bellows {

ControlCore::ControlCore(const ControllerParameters& controller, const TimingParameters& timing)
    : controller_(controller), timing_(timing) {
  loops_.reserve(kMaxJoints);
  for (int j = 0; j < kMaxJoints; ++j) {
    loops_.push_back(JointLoop{PidController(controller, timing.sample_s()),
                               PressureController(controller),
                               PressureController(controller),
                               {}});
    reset_loop(loops_.back());
  }
}

void ControlCore::reset_loop(JointLoop& l) const {
  l.pid.reset();
  l.pressure_a.reset();
  l.pressure_b.reset();
  l.setpoints = map_setpoints(0.0, controller_.gas.ambient_bar, controller_.p_max_bar);
  l.hold_rad = l.desired_rad = l.u_total_bar = 0.0;
}

void ControlCore::use_joints(int joints) {
  joints_ = std::clamp(joints, 1, kMaxJoints);  // callers pass 1..kMaxJoints; never index beyond
  for (int j = joints_; j < kMaxJoints; ++j) reset_loop(loop(j));
}

void ControlCore::reset_pids() {
  for (JointLoop& l : loops_) l.pid.reset();
}

void ControlCore::hold(double angle_rad) { hold(JointVector::Constant(1, angle_rad)); }

void ControlCore::hold(const JointVector& angles_rad) {
  use_joints(static_cast<int>(angles_rad.size()));
  for (int j = 0; j < joints_; ++j) loop(j).hold_rad = angles_rad(j);
  trajectory_ = nullptr;
}

void ControlCore::start_trial(const Trajectory& trajectory, const Eigen::VectorXd& correction_bar,
                              TrialRecord& record) {
  start(trajectory, correction_bar.data(), correction_bar.size(), 1, record);
}

void ControlCore::start_trial(const Trajectory& trajectory, const Eigen::MatrixXd& correction_bar,
                              TrialRecord& record) {
  start(trajectory, correction_bar.data(), correction_bar.rows(), correction_bar.cols(), record);
}

void ControlCore::start(const Trajectory& trajectory, const double* correction_bar, Eigen::Index rows,
                        Eigen::Index columns, TrialRecord& record) {
  use_joints(trajectory.joints());
  record.prepare(trajectory.learning_samples(), timing_.ticks_per_sample, joints_);
  trajectory_ = &trajectory;
  correction_ = correction_bar;
  correction_rows_ = rows;
  correction_columns_ = columns;
  record_ = &record;
  sample_ = 0;
  tick_in_sample_ = 0;
  tick_in_trial_ = 0;
}

double ControlCore::correction_bar(int sample, int joint) const {
  if (sample >= correction_rows_ || joint >= correction_columns_) return 0.0;
  return correction_[joint * correction_rows_ + sample];
}

void ControlCore::abort_trial() {
  for (int j = 0; j < joints_; ++j) loop(j).hold_rad = loop(j).desired_rad;
  trajectory_ = nullptr;
}

void ControlCore::set_controller_gains(const ControllerParameters& params) {
  controller_.k_ff = params.k_ff;
  controller_.k_p = params.k_p;
  controller_.k_i_per_s = params.k_i_per_s;
  controller_.k_d_s = params.k_d_s;
  for (JointLoop& l : loops_) l.pid.set_gains(controller_);
}

ControlCore::JointState ControlCore::JointLoop::state() const {
  return {pid.state(), pressure_a.state(), pressure_b.state(), setpoints, hold_rad, desired_rad, u_total_bar};
}

void ControlCore::JointLoop::set_state(const JointState& state) {
  pid.set_state(state.pid);
  pressure_a.set_state(state.pressure_a);
  pressure_b.set_state(state.pressure_b);
  setpoints = state.setpoints;
  hold_rad = state.hold_rad;
  desired_rad = state.desired_rad;
  u_total_bar = state.u_total_bar;
}

ControlCore::State ControlCore::state() const {
  State s;
  s.tick_in_sample = tick_in_sample_;
  s.joint_count = joints_;
  for (int j = 0; j < joints_; ++j) s.joints[static_cast<std::size_t>(j)] = loop(j).state();
  return s;
}

void ControlCore::set_state(const State& state) {
  trajectory_ = nullptr;
  use_joints(state.joint_count);
  for (int j = 0; j < joints_; ++j) loop(j).set_state(state.joints[static_cast<std::size_t>(j)]);
  tick_in_sample_ = state.tick_in_sample;
}

void ControlCore::run_sample(const SensorReading& reading) {
  const bool recording = trajectory_ != nullptr;
  const int k = sample_;
  if (recording) record_->sample_time_s(k) = k * trajectory_->sample_time_s;
  for (int j = 0; j < joints_; ++j) {
    JointLoop& c = loop(j);
    const JointReading& r = reading.joint[static_cast<std::size_t>(j)];
    const double measured = r.angle_rad / std::numbers::pi;
    double u_ilc = 0.0;
    if (recording) {
      c.desired_rad = trajectory_->joint(j)(k);
      TrialSamples& s = record_->joint_samples(j);
      s.setpoint_rad(k) = c.desired_rad;
      s.angle_rad(k) = r.angle_rad;
      s.error_rad(k) = k == 0 ? 0.0 : c.desired_rad - r.angle_rad;
      s.pressure_a_bar(k) = r.chamber_bar[0];
      s.pressure_b_bar(k) = r.chamber_bar[1];
      if (k < trajectory_->learning_samples()) u_ilc = correction_bar(k, j);
    } else {
      c.desired_rad = c.hold_rad;
    }
    const double u_pid = c.pid.step(c.desired_rad / std::numbers::pi, measured, c.setpoints.saturation_sign);
    c.u_total_bar = u_pid + u_ilc;
    c.setpoints = map_setpoints(c.u_total_bar, controller_.gas.ambient_bar, controller_.p_max_bar);
    if (recording) {
      TrialSamples& s = record_->joint_samples(j);
      s.u_pid_bar(k) = u_pid;
      s.u_ilc_bar(k) = u_ilc;
      s.u_total_bar(k) = c.u_total_bar;
      s.setpoint_a_bar(k) = c.setpoints.a_bar;
      s.setpoint_b_bar(k) = c.setpoints.b_bar;
    }
  }
  if (recording) end_trial_at(k);
}

void ControlCore::end_trial_at(int k) {
  if (k != trajectory_->learning_samples()) return;
  record_->complete = true;
  hold(trajectory_->setpoint_rad(k));
}

void ControlCore::hold_sample(const SensorReading& last) {
  if (trajectory_ == nullptr) return;  // holding: the hold angle stays
  const int k = sample_;
  record_->held[static_cast<std::size_t>(k)] = 1;
  ++record_->held_samples;
  record_->sample_time_s(k) = k * trajectory_->sample_time_s;
  for (int j = 0; j < joints_; ++j) {
    JointLoop& c = loop(j);
    const JointReading& r = last.joint[static_cast<std::size_t>(j)];
    c.desired_rad = trajectory_->joint(j)(k);
    TrialSamples& s = record_->joint_samples(j);
    s.setpoint_rad(k) = c.desired_rad;
    s.angle_rad(k) = r.angle_rad;  // the last reading: no measurement of this sample
    s.error_rad(k) = 0.0;          // not learned from
    s.pressure_a_bar(k) = r.chamber_bar[0];
    s.pressure_b_bar(k) = r.chamber_bar[1];
    const int in_force = k > 0 ? k - 1 : 0;  // the inputs and set points in force
    s.u_pid_bar(k) = k > 0 ? s.u_pid_bar(in_force) : 0.0;
    s.u_ilc_bar(k) = k > 0 ? s.u_ilc_bar(in_force) : 0.0;
    s.u_total_bar(k) = c.u_total_bar;
    s.setpoint_a_bar(k) = c.setpoints.a_bar;
    s.setpoint_b_bar(k) = c.setpoints.b_bar;
  }
  end_trial_at(k);
}

ValveCommand ControlCore::tick(const SensorReading& reading) { return step(reading, true); }

ValveCommand ControlCore::tick_held(const SensorReading& last) { return step(last, false); }

ValveCommand ControlCore::step(const SensorReading& reading, bool fresh) {
  // A reading of another arm: nothing of it may drive these controllers (see the header).
  if (reading.joint_count != joints_) return ValveCommand::vented(joints_);
  if (tick_in_sample_ == 0) {
    if (fresh) run_sample(reading);
    else hold_sample(reading);
  }
  const bool recording = trajectory_ != nullptr;
  ValveCommand command;
  command.joint_count = joints_;
  if (recording) {
    record_->tick_time_s(tick_in_trial_) = tick_in_trial_ * timing_.tick_s;
    record_->supply_bar(tick_in_trial_) = reading.supply_bar;
  }
  for (int j = 0; j < joints_; ++j) {
    JointLoop& c = loop(j);
    const JointReading& r = reading.joint[static_cast<std::size_t>(j)];
    // Held: every valve closed, the pressure controllers not stepped on a reading they have seen.
    const DutyCycles a =
        fresh ? c.pressure_a.step(c.setpoints.a_bar, r.chamber_bar[0], reading.supply_bar) : DutyCycles{};
    const DutyCycles b =
        fresh ? c.pressure_b.step(c.setpoints.b_bar, r.chamber_bar[1], reading.supply_bar) : DutyCycles{};
    JointValves& valves = command.joint[static_cast<std::size_t>(j)];
    valves.inlet_duty = {a.inlet, b.inlet};
    valves.outlet_duty = {a.outlet, b.outlet};
    if (recording) {
      TrialTicks& t = record_->joint_ticks(j);
      const int i = tick_in_trial_;
      t.angle_rad(i) = r.angle_rad;
      t.pressure_a_bar(i) = r.chamber_bar[0];
      t.pressure_b_bar(i) = r.chamber_bar[1];
      t.setpoint_a_bar(i) = c.setpoints.a_bar;
      t.setpoint_b_bar(i) = c.setpoints.b_bar;
      t.inlet_a(i) = a.inlet;
      t.outlet_a(i) = a.outlet;
      t.inlet_b(i) = b.inlet;
      t.outlet_b(i) = b.outlet;
    }
  }
  if (recording) ++tick_in_trial_;
  if (++tick_in_sample_ == timing_.ticks_per_sample) {
    tick_in_sample_ = 0;
    if (trajectory_ != nullptr) ++sample_;
  }
  return command;
}

}  // namespace bellows
