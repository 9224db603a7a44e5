// Learning that carries over: the first correction for a new trajectory, computed from trials of
// other trajectories on the same arm (issue 13; docs/learning-laws.md, "Transfer"). Its callers:
// app/transfer_sources loads the saved sessions (`run --transfer-from`), ui/console_transfer offers
// the result in the console.
//
// Every method predicts the *total* input the arm needs to follow a reference, u_tot = F(r), as a
// linear map of the reference fitted by ridge least squares, and subtracts what the target's PID will
// contribute when tracking well (k_ff r - k_d r_dot): fitting totals, not corrections, makes sessions
// with other PID gains usable. The methods differ in what F is fitted to:
//   reference-fir  non-causal FIR (+ slow low-passes) of r -> u_tot of each source's last trial
//   basis          differences of r up to 4th order + slow low-passes (van de Wijdeven and Bosgra's
//                  basis functions, with fixed-pole rational terms after Bolder and Oomen)
//   inverse-fir    non-causal FIR of the measured angle y -> u_tot, over *every* trial of every source
//                  (a plant inverse identified from (y, u) pairs)
//   auto           the method whose held-out prediction is best
// Safety: a closed-loop model G (causal FIR, u_ilc -> change of the error) and a feedback-only error
// model e0(r) are fitted from the same trials; the first trial's error is predicted as e0 - G u. A
// transfer whose prediction on the new reference, or on a held-out source session, is not better than
// feedback only is replaced by zero, and the result says why. The correction is clamped so that the
// expected feedback plus the correction stays inside the pressure limits.
#pragma once

#include <array>
#include <string>
#include <vector>

#include <Eigen/Dense>

#include "engine/config/configuration.hpp"
#include "engine/learning/learning_transfer_fit.hpp"
#include "engine/base/parameters.hpp"
#include "engine/trial/trajectory.hpp"

namespace bellows {

/// One trial of a source: what reached the arm and what it did. N = the source's learning samples.
struct TransferTrial {
  Eigen::VectorXd u_ilc_bar;  // N, the correction applied
  Eigen::VectorXd u_pid_bar;  // N, the feedback
  Eigen::VectorXd angle_rad;  // N + 1, measured
};

/// A source session reduced to what transfer uses.
struct TransferSource {
  std::string name;
  Trajectory trajectory;
  ControllerParameters controller;
  std::vector<TransferTrial> trials;  // in iteration order; the last is the best-learned
};

/// Why trials recorded with `source` on the device `source_device` cannot teach a run with `target`
/// on `target_device` (another sample time, device, or simulated arm: a physical [plant] key differs);
/// empty when they can. Gains, weights, laws, seeds and lengths may differ.
std::string transfer_mismatch(const Configuration& source, const std::string& source_device,
                              const Configuration& target, const std::string& target_device);

/// Why trials recorded with the rig profile `source_profile` (a session's device_info "rig_profile";
/// empty when it had none) cannot teach a run with `target_profile`: another rig profile is another
/// arm, or the same arm wired otherwise. Empty when they can or `target_profile` is empty (not compared).
std::string rig_profile_mismatch(const std::string& source_profile, const std::string& target_profile);

enum class TransferMethod { kAuto, kReferenceFir, kBasis, kInverseFir };
inline constexpr std::array<TransferMethod, 4> kTransferMethods{TransferMethod::kAuto, TransferMethod::kReferenceFir,
                                                                TransferMethod::kBasis, TransferMethod::kInverseFir};
std::string transfer_method_name(TransferMethod method);
/// Every method's name in kTransferMethods' order: "auto, reference-fir, basis or inverse-fir".
std::string transfer_method_names();
/// "auto", "reference-fir", "basis", "inverse-fir"; throws InputError otherwise.
TransferMethod parse_transfer_method(const std::string& name);

struct TransferSettings {
  TransferMethod method = TransferMethod::kAuto;
  int taps_behind = 25;  // reference samples before the output sample (0.5 s at 50 Hz)
  int taps_ahead = 12;   // and after it: the correction leads the reference
  std::vector<double> slow_time_constants_s = {0.3, 1.0, 3.0};  // creep and the integral's tails
  double relative_ridge = 1e-5;
  std::vector<int> nonlinear_leads = {-6, -3, 0, 3, 6, 9};  // samples; see RegressorShape
  int closed_loop_taps = 40;                                // G, the correction's effect on the error (0.8 s)
  double limit_margin_bar = 0.01;        // keep expected feedback + correction this far inside the limits
  double largest_accepted_ratio = 0.95;  // predicted RMS / feedback-only RMS above this: fall back to zero
};

enum class TransferStatus {
  kTransferred,  // a correction was computed and is predicted to help
  kFallback,     // the correction is zero; `reason` says why
};

struct TransferResult {
  TransferStatus status = TransferStatus::kFallback;
  std::string method;                            // the method used (or tried, on fallback)
  std::string reason;                            // why it fell back; empty when transferred
  Eigen::VectorXd correction_bar;                // N of the target; zero on fallback
  double predicted_feedback_only_rms_deg = 0.0;  // the new trajectory's first trial without transfer
  double predicted_rms_deg = 0.0;                // with this correction (equal on fallback)
  double validation_ratio =
      0.0;  // predicted / measured-feedback-only RMS on held-out source sessions (in-sample with one source)
  int clamped_samples = 0;                                    // samples the pressure limits cut
  std::vector<std::pair<std::string, double>> method_ratios;  // every method's validation ratio (auto)
};

struct TransferInfo {
  int sources = 0;
  int trials = 0;
  long fitted_rows = 0;
  bool ready = false;
};

class LearningTransfer {
 public:
  explicit LearningTransfer(TransferSettings settings = {});

  /// Fits the closed-loop and feedback-only error models and the inverse models from the sources.
  /// Every source must have the target's sample time and at least one complete trial; throws
  /// InputError naming the source otherwise.
  void setup(std::vector<TransferSource> sources, const ControllerParameters& target_controller, double sample_time_s);
  /// The first correction for `target` (its sample time must match). Never throws for a fitted
  /// transfer: when it cannot help, the result falls back to zero and says why.
  TransferResult solve(const Trajectory& target) const;
  const TransferInfo& info() const { return info_; }

 private:
  Eigen::VectorXd inverse_theta(TransferMethod method, int left_out) const;
  Eigen::VectorXd predict_correction(TransferMethod method, const Eigen::VectorXd& theta, const Trajectory& target,
                                     const ControllerParameters& controller, int* clamped) const;
  Eigen::VectorXd predicted_error_change(const Eigen::VectorXd& correction) const;
  Eigen::VectorXd predicted_feedback_error(const Trajectory& target) const;
  double validation_ratio(TransferMethod method) const;

  TransferSettings settings_;
  std::vector<TransferSource> sources_;
  ControllerParameters target_controller_;
  double sample_time_s_ = 0.0;
  Eigen::VectorXd closed_loop_theta_;           // G
  Eigen::VectorXd feedback_error_theta_;        // e0(r)
  std::vector<RidgeAccumulator> inverse_fits_;  // per method of kMethods, by source
  std::vector<Eigen::VectorXd> theta_all_;      // per method (index = enum), fitted on all sources
  TransferInfo info_;
};

}  // namespace bellows
