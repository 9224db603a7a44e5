// A learning law: between trials, the next correction u_{j+1} from the last one u_j and the
// trial's normalized error e_j = (yD - y) / pi at samples 1..N. Laws are built once per model,
// weights and trial length (their expensive set-up happens there) and then updated per trial.
#pragma once

#include <complex>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Dense>

namespace bellows {

/// How a linear, time-invariant law acts on one frequency of an everlasting trial:
/// U_{j+1} = from_correction * U_j + from_error * E_j (E_j the error at samples 1..N).
struct LawFrequencyResponse {
  std::complex<double> from_correction;
  std::complex<double> from_error;
};

/// How well the model that planned a trial's correction predicted what the trial did: for laws that
/// learn their model from the trials (noilc-learned), from their second update on. Norms over the
/// trial's samples (and joints) of the normalized error e = (yD - y) / pi.
struct ModelCheck {
  int trial = 0;                  // the law's updates so far: the check is of the trial the last one read
  double predicted_change = 0.0;  // ||P_model (u_j - u_{j-1})||: the change of output the model predicted
  double measured_change = 0.0;   // ||e_{j-1} - e_j||: the change the trial showed
  double miss = 0.0;              // ||measured - predicted|| / ||measured||
  bool refitted = false;          // the model was refit from the trial
  bool fell_back = false;         // the trial got worse: the model fell half way back to its prior
};

class LearningLaw {
 public:
  virtual ~LearningLaw() = default;
  /// u_next = law(u_j, e_j); all three have N entries. u_next may not alias the inputs.
  virtual void update(const Eigen::Ref<const Eigen::VectorXd>& u_j, const Eigen::Ref<const Eigen::VectorXd>& e_j,
                      Eigen::Ref<Eigen::VectorXd> u_next) = 0;
  /// The configuration name of the law, e.g. "noilc-dense".
  virtual std::string name() const = 0;
  virtual int samples() const = 0;

  /// What the last trial's feedback contributed, u_pid(0..N-1) in bar, and the largest |u_pid + u_ilc|
  /// the set-point clamp lets through (p_max - p0). Called before update(); laws that keep the
  /// correction within the pressure limits use it, the others ignore it.
  virtual void set_input_context(const Eigen::Ref<const Eigen::VectorXd>& /*feedback_bar*/,
                                 double /*input_limit_bar*/) {}

  /// Which samples k = 0..N of the last trial were held (no fresh reading: error 0, TrialRecord::held).
  /// Called before update(); laws that learn a model from the trials leave those outputs out.
  virtual void set_held_outputs(const std::vector<unsigned char>& /*held*/) {}

  /// The law's frequency response at `theta_rad_per_sample` in (0, pi], for convergence prediction;
  /// empty for laws that are not linear and time-invariant away from the trial's ends.
  virtual std::optional<LawFrequencyResponse> frequency_response(double /*theta_rad_per_sample*/) const {
    return std::nullopt;
  }

  /// What the law has to say for the session's events since the last call (a model refit, a fall-back),
  /// then forgotten; empty for laws that never say anything.
  virtual std::string take_note() { return {}; }

  /// After update(): the last trial against its model's prediction; empty for laws without a model
  /// that learns (and before their second update).
  virtual std::optional<ModelCheck> model_check() const { return std::nullopt; }
};

}  // namespace bellows
