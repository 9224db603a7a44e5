#include "engine/control_core.hpp"

#include <numbers>

namespace bellows {

ControlCore::ControlCore(const ControllerParameters& controller, const TimingParameters& timing)
    : controller_(controller),
      timing_(timing),
      pid_(controller, timing.sample_s()),
      pressure_a_(controller),
      pressure_b_(controller) {
  setpoints_ = map_setpoints(0.0, controller.gas.ambient_bar, controller.p_max_bar);
}

void ControlCore::hold(double angle_rad) {
  hold_rad_ = angle_rad;
  trajectory_ = nullptr;
}

void ControlCore::start_trial(const Trajectory& trajectory, const Eigen::VectorXd& correction_bar, TrialRecord& record) {
  record.prepare(trajectory.learning_samples(), timing_.ticks_per_sample);
  trajectory_ = &trajectory;
  correction_ = &correction_bar;
  record_ = &record;
  sample_ = 0;
  tick_in_sample_ = 0;
  tick_in_trial_ = 0;
}

void ControlCore::abort_trial() {
  hold_rad_ = desired_rad_;
  trajectory_ = nullptr;
}

void ControlCore::set_controller_gains(const ControllerParameters& params) {
  controller_.k_ff = params.k_ff;
  controller_.k_p = params.k_p;
  controller_.k_i_per_s = params.k_i_per_s;
  controller_.k_d_s = params.k_d_s;
  pid_.set_gains(controller_);
}

ControlCore::State ControlCore::state() const {
  return {pid_.state(), pressure_a_.state(), pressure_b_.state(), setpoints_, hold_rad_, desired_rad_, u_total_bar_,
          tick_in_sample_};
}

void ControlCore::set_state(const State& state) {
  trajectory_ = nullptr;
  pid_.set_state(state.pid);
  pressure_a_.set_state(state.pressure_a);
  pressure_b_.set_state(state.pressure_b);
  setpoints_ = state.setpoints;
  hold_rad_ = state.hold_rad;
  desired_rad_ = state.desired_rad;
  u_total_bar_ = state.u_total_bar;
  tick_in_sample_ = state.tick_in_sample;
}

void ControlCore::run_sample(const SensorReading& reading) {
  const double measured = reading.joint[0].angle_rad / std::numbers::pi;
  double u_ilc = 0.0;
  if (trajectory_ != nullptr) {
    const int k = sample_;
    desired_rad_ = trajectory_->angle_rad(k);
    TrialSamples& s = record_->samples;
    s.time_s(k) = k * trajectory_->sample_time_s;
    s.setpoint_rad(k) = desired_rad_;
    s.angle_rad(k) = reading.joint[0].angle_rad;
    s.error_rad(k) = k == 0 ? 0.0 : desired_rad_ - reading.joint[0].angle_rad;
    s.pressure_a_bar(k) = reading.joint[0].chamber_bar[0];
    s.pressure_b_bar(k) = reading.joint[0].chamber_bar[1];
    if (k < trajectory_->learning_samples()) u_ilc = (*correction_)(k);
  } else {
    desired_rad_ = hold_rad_;
  }
  const double u_pid = pid_.step(desired_rad_ / std::numbers::pi, measured, setpoints_.saturation_sign);
  u_total_bar_ = u_pid + u_ilc;
  setpoints_ = map_setpoints(u_total_bar_, controller_.gas.ambient_bar, controller_.p_max_bar);
  if (trajectory_ != nullptr) {
    TrialSamples& s = record_->samples;
    s.u_pid_bar(sample_) = u_pid;
    s.u_ilc_bar(sample_) = u_ilc;
    s.u_total_bar(sample_) = u_total_bar_;
    s.setpoint_a_bar(sample_) = setpoints_.a_bar;
    s.setpoint_b_bar(sample_) = setpoints_.b_bar;
    if (sample_ == trajectory_->learning_samples()) {
      record_->complete = true;
      hold(trajectory_->angle_rad(sample_));
    }
  }
}

ValveCommand ControlCore::tick(const SensorReading& reading) {
  if (tick_in_sample_ == 0) run_sample(reading);
  const bool recording = trajectory_ != nullptr;
  const DutyCycles a = pressure_a_.step(setpoints_.a_bar, reading.joint[0].chamber_bar[0], reading.supply_bar);
  const DutyCycles b = pressure_b_.step(setpoints_.b_bar, reading.joint[0].chamber_bar[1], reading.supply_bar);
  ValveCommand command;
  command.joint[0].inlet_duty = {a.inlet, b.inlet};
  command.joint[0].outlet_duty = {a.outlet, b.outlet};
  if (recording) {
    TrialTicks& t = record_->ticks;
    const int i = tick_in_trial_;
    t.time_s(i) = i * timing_.tick_s;
    t.angle_rad(i) = reading.joint[0].angle_rad;
    t.pressure_a_bar(i) = reading.joint[0].chamber_bar[0];
    t.pressure_b_bar(i) = reading.joint[0].chamber_bar[1];
    t.supply_bar(i) = reading.supply_bar;
    t.setpoint_a_bar(i) = setpoints_.a_bar;
    t.setpoint_b_bar(i) = setpoints_.b_bar;
    t.inlet_a(i) = a.inlet;
    t.outlet_a(i) = a.outlet;
    t.inlet_b(i) = b.inlet;
    t.outlet_b(i) = b.outlet;
    ++tick_in_trial_;
  }
  if (++tick_in_sample_ == timing_.ticks_per_sample) {
    tick_in_sample_ = 0;
    if (trajectory_ != nullptr) ++sample_;
  }
  return command;
}

}  // namespace bellows
