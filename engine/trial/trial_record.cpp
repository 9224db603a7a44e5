#include "engine/trial/trial_record.hpp"

#include <cmath>
#include <numbers>

namespace bellows {

void TrialSamples::resize(Eigen::Index count) {
  for (Eigen::VectorXd* v : {&time_s, &setpoint_rad, &angle_rad, &error_rad, &u_pid_bar, &u_ilc_bar, &u_total_bar,
                             &pressure_a_bar, &pressure_b_bar, &setpoint_a_bar, &setpoint_b_bar}) {
    v->setZero(count);
  }
}

void TrialTicks::resize(Eigen::Index count) {
  for (Eigen::VectorXd* v : {&time_s, &angle_rad, &pressure_a_bar, &pressure_b_bar, &supply_bar, &setpoint_a_bar,
                             &setpoint_b_bar, &inlet_a, &outlet_a, &inlet_b, &outlet_b}) {
    v->setZero(count);
  }
}

void TrialRecord::prepare(int learning_samples_count, int ticks_per_sample, int joints) {
  learning_samples = learning_samples_count;
  const std::size_t more = joints > 1 ? static_cast<std::size_t>(joints - 1) : 0;
  more_joint_samples.resize(more);
  more_joint_ticks.resize(more);
  for (int j = 0; j < this->joints(); ++j) {
    joint_samples(j).resize(learning_samples_count + 1);
    joint_ticks(j).resize(static_cast<Eigen::Index>(learning_samples_count) * ticks_per_sample);
  }
  held.assign(static_cast<std::size_t>(learning_samples_count + 1), 0);  // within its capacity: no allocation
  held_samples = 0;
  complete = false;
}

Eigen::VectorXd TrialRecord::normalized_error() const {
  return samples.error_rad.tail(learning_samples) / std::numbers::pi;
}

Eigen::MatrixXd TrialRecord::normalized_joint_errors() const {
  Eigen::MatrixXd errors(learning_samples, joints());
  for (int j = 0; j < joints(); ++j)
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
  return samples.error_rad.tail(learning_samples).cwiseAbs().maxCoeff() * 180.0 / std::numbers::pi;
}

}  // namespace bellows
