// Convergence prediction: before a run, how fast the chosen law should learn and whether it may
// diverge, for the nominal model and over a grid of model errors.
//
// Method (frequency domain, long-trial approximation): a linear, time-invariant law acts on each
// frequency theta as U_{j+1} = Lu U_j + Le E_j. The correction reaches the arm through the PID loop,
// so the true map from correction to error is the closed loop Pcl = z G / (1 + G C_pid), G the arm
// (kappa and omega0 scaled by the model error) behind the pressure controllers' designed first-order
// response (tau_p), including the damping of the bellows' volume change with angle ([model]
// volume_gain), which the pressure loop leaves uncompensated. Then U_{j+1} = lambda U_j + Le R with lambda = Lu - Le
// Pcl: each frequency of the correction (and of the error) contracts by |lambda| per trial. The predicted contraction
// is the largest |lambda| over the frequencies a trial of N samples resolves, [1/(N T), Nyquist]; above 1 somewhere,
// learning may diverge there.
#pragma once

#include <string>
#include <vector>

#include "engine/base/cancellation.hpp"
#include "engine/config/configuration.hpp"
#include "engine/learning/learning_law.hpp"

namespace bellows {

struct ContractionEstimate {
  double kappa_scale = 1.0;   // true kappa / nominal kappa
  double omega0_scale = 1.0;  // true omega0 / nominal omega0
  double contraction = 0.0;   // max |lambda| over the band
  double worst_frequency_hz = 0.0;
};

struct ConvergencePrediction {
  bool available = false;  // false for laws without a frequency response
  double band_low_hz = 0.0, band_high_hz = 0.0;
  double model_error = 0.0;  // the grid spans 1 -+ model_error in kappa and omega0
  ContractionEstimate nominal;
  ContractionEstimate worst;  // over the grid
  std::vector<ContractionEstimate> grid;
  int diverging_points = 0;  // grid points with contraction > 1 + 1e-3
  std::string warning;       // empty when every grid point contracts
};

/// |lambda| up to 1 + this counts as "not diverging": such a mode needs ~700 trials to double, and
/// laws that barely learn near Nyquist (gradient) sit at |lambda| = 1 within rounding there.
inline constexpr double kDivergenceTolerance = 1e-3;

/// The warning of a prediction whose nominal contraction, or a grid point's, exceeds 1 (law
/// `law_name` named in it); empty when every point contracts.
std::string convergence_warning(const ConvergencePrediction& prediction, const std::string& law_name);

/// The prediction for `law` on trials of `samples` samples, with the grid of [ilc] prediction_*.
/// Throws Cancelled when `stop` is set (looked at between grid points).
ConvergencePrediction predict_convergence(const LearningLaw& law, const Configuration& config, int samples,
                                          StopFlag stop = nullptr);

}  // namespace bellows
