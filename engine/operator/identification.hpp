// Model identification: fits the nominal model's kappa, omega0 and delta (spec section 2) to a
// recorded trial by least squares on the output error.
//
// The model input is the *measured* pressure difference pA - pB and the output the measured angle,
// both at the tick rate: that is the relation the nominal model describes (the pressure
// controllers' lag is not part of it). The fit starts from an ARX (equation-error) estimate, whose
// poles and gain give kappa, omega0 and delta, and refines it by Levenberg-Marquardt on the
// simulated-versus-measured angle, which noise in the angle does not bias.
//
// Why the input is a reconstructed tick mean and not the sampled pressure: the switching valves
// open at the start of each PWM period (one tick), right after the pressures are read, while the
// bellows' volume changes with the arm all tick long. The pressure controller's pulses that cancel
// that volume effect are therefore invisible in the tick-start samples, and an input error
// proportional to the arm's velocity appears: fitted naively, the damping comes out ~15 % low.
#pragma once

#include <Eigen/Dense>

#include "engine/base/cancellation.hpp"
#include "engine/base/parameters.hpp"
#include "engine/trial/trial_record.hpp"

namespace bellows {

/// Input and output of one identification trial at a uniform step.
struct IdentificationData {
  double sample_time_s = 0.0;
  Eigen::VectorXd pressure_difference_bar;  // measured pA - pB
  Eigen::VectorXd angle_rad;                // measured
};

/// The tick-rate record of a trial as identification data. The input of tick k is the mean pressure
/// difference over the tick, reconstructed from the readings at its ends and the valve commands
/// with the controller's nominal valve model (see identification.cpp). Of joint `joint` (0-based).
IdentificationData identification_data(const TrialRecord& record, const ControllerParameters& controller, double tick_s,
                                       int joint = 0);

/// The angle the model predicts for the data's pressure difference (held over each step), from the
/// data's first angle with the arm at rest.
Eigen::VectorXd simulate_arm_angle(const ModelParameters& model, const IdentificationData& data);

/// Normalized fit in percent: 100 (1 - ||y - y_hat|| / ||y - mean(y)||); 100 is perfect.
double normalized_fit_percent(const Eigen::VectorXd& measured, const Eigen::VectorXd& predicted);

struct ArmModelFit {
  ModelParameters model;
  ModelParameters initial;   // the ARX estimate the refinement started from
  double fit_percent = 0.0;  // on the fitted data
  double rms_residual_deg = 0.0;
  int iterations = 0;
  bool converged = false;
};

/// Least-squares fit. `fallback` is the start when the ARX estimate is not a stable oscillator.
/// Throws InputError when the data are too short or carry no excitation, Cancelled when `stop` is set
/// (looked at before each model simulation).
ArmModelFit fit_arm_model(const IdentificationData& data, const ModelParameters& fallback, StopFlag stop = nullptr);

}  // namespace bellows
