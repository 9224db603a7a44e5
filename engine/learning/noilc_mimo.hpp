// Norm-optimal ILC for J joints in O(N): the multi-input multi-output form of the paper's optimum
// (spec section 5, engine/learning/noilc_riccati for one joint). With u(t), e(t) in R^J and J x J weights
// M, S, W (symmetric, positive semidefinite; diagonal = per joint):
//
//   J(u_{j+1}) = 1/2 sum_t [ e_{j+1}(t)' M e_{j+1}(t) + v(t)' S v(t) + (Du)(t)' W (Du)(t) ]
//                + (rho/2) ||u_{j+1} - target||^2,        v = u_{j+1} - u_j,  e_{j+1} = e_j - P v
//
// D the forward difference divided by T per joint (last row repeating the one before). The Riccati
// form is the single-joint one with matrix-valued stages: the state is augmented with v(t-1), the
// scalar curvature becomes a J x J matrix whose Cholesky factor is taken per stage in setup().
// setup() allocates (gains for N stages); solve() allocates nothing and is one backward and one
// forward pass: O(N J^2) time (stage matrices J x 3J applied to vectors; only setup() is O(N J^3)),
// O(N J^2) memory. docs/learning-laws.md ("Several joints").
//
// Data are N x J matrices, one column per joint (column j = that joint's trial, as for one joint).
#pragma once

#include <cstddef>
#include <memory>
#include <span>

#include "engine/model/multi_joint_model.hpp"
#include "engine/base/parameters.hpp"

namespace bellows {

/// The weights of the cost above, each J x J. Diagonal weights weigh each joint on its own.
struct MultiJointWeights {
  JointMatrix m, s, w;

  /// Every joint with the single-joint weights m, s, w of `weights`.
  static MultiJointWeights uniform(const IlcParameters& weights, int joints);
  /// Joint i with the weights of `per_joint[i]` (diagonal matrices).
  static MultiJointWeights per_joint(std::span<const IlcParameters> per_joint);
};

enum class MultiJointNoilcStatus {
  kOk,
  kNotSetUp,             // solve() before a successful setup()
  kBadJointCount,        // J outside 1..kMaxJoints
  kTooFewSamples,        // N < 2
  kBadModel,             // A, B, C not 2J x 2J, 2J x J, J x 2J, or not finite, or T <= 0
  kBadWeights,           // a weight not J x J, not symmetric, not finite, or not positive semidefinite; rho < 0
  kNotPositiveDefinite,  // the cost is not strictly convex (e.g. S = W = 0 with a singular model)
  kShapeMismatch,        // solve()'s data are not N x J
  kNonFiniteData,        // solve()'s u_j, e_j or target hold a NaN or an infinity
  kBadBounds,            // constrained: bounds not N x J, NaN, or a lower bound above its upper bound
  kNotConverged,         // constrained: ADMM stopped at its iteration limit; the result is feasible, not optimal
};

const char* to_string(MultiJointNoilcStatus status);

struct MultiJointNoilcInfo {
  MultiJointNoilcStatus status = MultiJointNoilcStatus::kNotSetUp;  // of the last setup() or solve()
  int joints = 0;
  int samples = 0;
  double proximal_weight = 0.0;
  long solves = 0;               // successful solves since setup()
  std::size_t memory_bytes = 0;  // gains and workspace: what grows with N
};

class MultiJointNoilc {
 public:
  MultiJointNoilc();
  ~MultiJointNoilc();
  MultiJointNoilc(MultiJointNoilc&&) noexcept;
  MultiJointNoilc& operator=(MultiJointNoilc&&) noexcept;

  /// Computes the stage gains (backward Riccati sweep). On failure the solver is left not set up.
  MultiJointNoilcStatus setup(const MultiJointModel& model, const MultiJointWeights& weights, int samples,
                              double proximal_weight = 0.0);

  /// u_next = argmin J(u); `target` is read only when rho > 0. All N x J; u_next may not alias the
  /// inputs. On a status other than kOk, u_next is left unchanged. Allocates nothing for plain
  /// column-major matrices (Eigen::Ref would copy a strided argument).
  MultiJointNoilcStatus solve(const Eigen::Ref<const Eigen::MatrixXd>& u_j,
                              const Eigen::Ref<const Eigen::MatrixXd>& e_j,
                              const Eigen::Ref<const Eigen::MatrixXd>& target, Eigen::Ref<Eigen::MatrixXd> u_next);
  /// The plain norm-optimal update (no proximal term): solve(u_j, e_j, u_j, u_next).
  MultiJointNoilcStatus update(const Eigen::Ref<const Eigen::MatrixXd>& u_j,
                               const Eigen::Ref<const Eigen::MatrixXd>& e_j, Eigen::Ref<Eigen::MatrixXd> u_next) {
    return solve(u_j, e_j, u_j, u_next);
  }

  const MultiJointNoilcInfo& info() const { return info_; }

  class Stages;  // the sweeps, specialized per joint count (noilc_mimo.cpp)

 private:
  std::unique_ptr<Stages> stages_;
  MultiJointNoilcInfo info_;
};

}  // namespace bellows
