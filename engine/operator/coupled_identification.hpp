// Identification of an arm of J joints (`bellows identify` on an [arm] chain, docs/rig-bring-up.md):
// from J trials, joint k's reference excited in trial k while the other joints' PIDs hold theirs,
//  - each joint's single-joint model (kappa, omega0, delta) by the single-joint fit
//    (engine/operator/identification) on its own trial, its input its own pressure difference;
//  - the coupled model: the J x J matrices of q_ddot = per_angle q + per_velocity q_dot + per_bar dp
//    (engine/model/coupled_joint_dynamics: 2J states, the structure and order of the chain's linearization)
//    by output-error least squares over all J trials at once, every joint's measured pressure
//    difference in, every joint's angle out, Levenberg-Marquardt from the independent joints'
//    diagonal. The held joints are what shows the coupling: their PIDs push back against the
//    excited joint's reaction torques, and their pressures and small motions carry it.
// The data are deviations from where each trial starts at rest (the angle and the pressure
// difference of its first samples): a chain in a vertical plane holds its pose against gravity with
// a pressure difference that is not part of the linear model.
#pragma once

#include <span>
#include <vector>

#include <Eigen/Dense>

#include "engine/base/cancellation.hpp"
#include "engine/model/coupled_joint_dynamics.hpp"
#include "engine/operator/identification.hpp"
#include "engine/base/parameters.hpp"
#include "engine/trial/trial_record.hpp"

namespace bellows {

/// One trial of J joints at a uniform step: column j is joint j + 1.
struct JointIdentificationData {
  double sample_time_s = 0.0;
  Eigen::MatrixXd pressure_difference_bar;  // n x J, deviation from the trial's resting start
  Eigen::MatrixXd angle_rad;                // n x J, deviation from the trial's resting start
  int joints() const { return static_cast<int>(angle_rad.cols()); }
};

/// Every joint's tick-rate identification data (identification_data per joint), as deviations from
/// the mean of the trial's first `rest_s` (the arm at rest before the excitation fades in).
JointIdentificationData joint_identification_data(const TrialRecord& record, const ControllerParameters& controller,
                                                  double tick_s, double rest_s);
/// Joint `joint`'s columns as single-joint data (for fit_arm_model).
IdentificationData single_joint_data(const JointIdentificationData& data, int joint);

/// The angles (n x J) the dynamics predict for the data's pressure differences (held over each
/// step), from rest at the data's first angles.
Eigen::MatrixXd simulate_joint_angles(const CoupledJointDynamics& dynamics, const JointIdentificationData& data);

/// Each joint's normalized fit (percent, 100 perfect) of `dynamics` over all `trials` together.
JointVector joint_fit_percent(const CoupledJointDynamics& dynamics, std::span<const JointIdentificationData> trials);

struct CoupledModelFit {
  CoupledJointDynamics dynamics;
  CoupledJointDynamics initial;  // where the refinement started
  JointVector fit_percent;       // per joint, on the fitted trials
  double rms_residual_deg = 0.0;
  int iterations = 0;
  bool converged = false;
};

/// Output-error least squares of the 3 J^2 entries over `trials` (each of the same J joints, at
/// least 50 samples), from `initial`. Throws InputError for data that cannot be fitted (too short,
/// non-finite, joints differ, a joint never moved), Cancelled when `stop` is set.
CoupledModelFit fit_coupled_model(std::span<const JointIdentificationData> trials, const CoupledJointDynamics& initial,
                                  StopFlag stop = nullptr);

}  // namespace bellows
