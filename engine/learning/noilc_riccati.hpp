// Norm-optimal ILC in O(N): the paper's optimum (spec section 5) computed as a linear-quadratic
// tracking problem over the trial (../shared/spec/noilc-riccati.md). The unknown is the change
// v(t) = u_{j+1}(t) - u_j(t); the state is augmented with v(t-1) so that the rate penalty D'WD is
// a stage cost. The feedback gains depend only on the model and the weights and are computed once,
// at construction, by a backward Riccati sweep; a trial's update is then one backward pass for the
// affine terms and one forward pass: O(N) time and memory, nothing allocated.
//
// The solver also accepts a proximal term (rho/2)||u_{j+1} - target||^2: the inner step of the
// constraint-aware law (noilc_constrained) is this same sweep.
#pragma once

#include <cstddef>

#include "engine/model/arm_model.hpp"
#include "engine/learning/learning_law.hpp"
#include "engine/base/parameters.hpp"

namespace bellows {

class RiccatiNoilcSolver {
 public:
  /// Throws InputError when N < 2 or the weights do not make the cost positive definite.
  RiccatiNoilcSolver(const DiscreteArmModel& model, const IlcParameters& weights, int samples,
                     double proximal_weight = 0.0);

  /// u_next = argmin J(u) + (rho/2) ||u - target||^2, J the paper's cost for (u_j, e_j).
  /// `target` is read only when the proximal weight rho is positive. No argument may alias u_next.
  void solve(const Eigen::Ref<const Eigen::VectorXd>& u_j, const Eigen::Ref<const Eigen::VectorXd>& e_j,
             const Eigen::Ref<const Eigen::VectorXd>& target, Eigen::Ref<Eigen::VectorXd> u_next);

  int samples() const { return static_cast<int>(feedforward_.size()); }
  double proximal_weight() const { return proximal_weight_; }
  /// Bytes held by the gains and workspace (what grows with N).
  std::size_t memory_bytes() const;

 private:
  double rate_weight(int t) const;  // W_t of the spec: 0 at t = 0, doubled at t = N-1

  Eigen::Matrix2d A_;
  Eigen::Vector2d B_;
  Eigen::RowVector2d C_;
  double m_, s_, rate_weight_, proximal_weight_;
  Eigen::Matrix<double, 3, Eigen::Dynamic> gains_;  // K_t = [K_dx, K_vprev] per column
  Eigen::RowVectorXd inverse_curvature_;            // 1 / H_uu(t)
  Eigen::VectorXd feedforward_;                     // k_t, rewritten each solve
};

/// The default learning law `noilc`.
class NormOptimalRiccati final : public LearningLaw {
 public:
  NormOptimalRiccati(const DiscreteArmModel& model, const IlcParameters& weights, int samples);

  void update(const Eigen::Ref<const Eigen::VectorXd>& u_j, const Eigen::Ref<const Eigen::VectorXd>& e_j,
              Eigen::Ref<Eigen::VectorXd> u_next) override;
  std::string name() const override { return "noilc"; }
  int samples() const override { return solver_.samples(); }
  std::optional<LawFrequencyResponse> frequency_response(double theta_rad_per_sample) const override;

  std::size_t memory_bytes() const { return solver_.memory_bytes(); }

 private:
  DiscreteArmModel model_;
  IlcParameters weights_;
  RiccatiNoilcSolver solver_;
};

/// Frequency response of norm-optimal ILC on an everlasting trial (both noilc forms share it).
LawFrequencyResponse norm_optimal_frequency_response(const DiscreteArmModel& model, const IlcParameters& weights,
                                                     double theta_rad_per_sample);

}  // namespace bellows
