#include "engine/trial/trial_record.hpp"

#include <cmath>
#include <numbers>

namespace bellows {

void TrialSamples::resize(Eigen::Index count) {
  for (Eigen::VectorXd* v : {&setpoint_rad, &angle_rad, &error_rad, &u_pid_bar, &u_ilc_bar, &u_total_bar,
                             &pressure_a_bar, &pressure_b_bar, &setpoint_a_bar, &setpoint_b_bar}) {
    v->setZero(count);
  }
}

void TrialTicks::resize(Eigen::Index count) {
  for (Eigen::VectorXd* v : {&angle_rad, &pressure_a_bar, &pressure_b_bar, &setpoint_a_bar, &setpoint_b_bar, &inlet_a,
                             &outlet_a, &inlet_b, &outlet_b}) {
    v->setZero(count);
  }
}

void TrialRecord::prepare(int learning_samples_count, int ticks_per_sample, int joint_count) {
  learning_samples = learning_samples_count;
  const Eigen::Index tick_count = static_cast<Eigen::Index>(learning_samples_count) * ticks_per_sample;
  sample_time_s.setZero(learning_samples_count + 1);
  tick_time_s.setZero(tick_count);
  supply_bar.setZero(tick_count);
  joints.resize(static_cast<std::size_t>(joint_count > 0 ? joint_count : 1));
  for (TrialJoint& joint : joints) {
    joint.samples.resize(learning_samples_count + 1);
    joint.ticks.resize(tick_count);
  }
  held.assign(static_cast<std::size_t>(learning_samples_count + 1), 0);  // within its capacity: no allocation
  held_samples = 0;
  complete = false;
}

Eigen::VectorXd TrialRecord::normalized_error(int joint) const {
  return joint_samples(joint).error_rad.tail(learning_samples) / std::numbers::pi;
}

Eigen::MatrixXd TrialRecord::normalized_joint_errors() const {
  Eigen::MatrixXd errors(learning_samples, joint_count());
  for (int j = 0; j < joint_count(); ++j)
    errors.col(j) = joint_samples(j).error_rad.tail(learning_samples) / std::numbers::pi;
  return errors;
}

double TrialRecord::rms_error_deg() const { return joint_rms_error_deg(0); }

double TrialRecord::joint_rms_error_deg(int joint) const {
  if (learning_samples == 0) return 0.0;
  const Eigen::VectorXd e = joint_samples(joint).error_rad.tail(learning_samples);
  return std::sqrt(e.squaredNorm() / learning_samples) * 180.0 / std::numbers::pi;
}

double TrialRecord::max_abs_error_deg() const {
  if (learning_samples == 0) return 0.0;
  return joint_samples(0).error_rad.tail(learning_samples).cwiseAbs().maxCoeff() * 180.0 / std::numbers::pi;
}

}  // namespace bellows
