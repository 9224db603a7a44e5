// Norm-optimal ILC in O(N) on any linear state-space model of the map from correction to output:
// x(t+1) = A x(t) + B u(t), y(t) = C x(t), n states, J inputs and outputs. The same cost and the same
// Riccati form as noilc_riccati (one joint, 2 states) and noilc_mimo (J joints, 2J states), for models
// of any order: the closed loop seen by the correction (arm, pressure lag, PID) and the learned
// corrections to it (engine/learning/closed_loop_model, noilc_learned).
//
// Set-up is a backward Riccati sweep that stops once the gains have settled (the stages between the
// first and the last few are time-invariant), so it runs for the settling stages only, and the gains
// are O(settling) in memory: the law refits its model between trials at the cost of one such sweep.
// A (the closed loop's blocks, the correction's shift register and low-passes) and B are sparse: a
// stage costs O(nnz(A) n + (n + J)^2 J), every product a column operation on dense storage, and the
// sweep's workspace is kept between set-ups of a model of the same size. solve() is one backward and
// one forward pass, O(N (nnz(A) + (n + J) J)), and allocates nothing.
#pragma once

#include <cstddef>
#include <vector>

#include <Eigen/Dense>
#include <Eigen/SparseCore>

namespace bellows {

struct StateSpaceModel {
  Eigen::MatrixXd A, B, C;  // n x n, n x J, J x n
  double sample_time_s = 0.0;
  int states() const { return static_cast<int>(A.rows()); }
  int inputs() const { return static_cast<int>(B.cols()); }
  /// y(1..N) from u(0..N-1) from rest, N x J (column per input): O(N (nnz(A) + n J)).
  Eigen::MatrixXd simulate(const Eigen::Ref<const Eigen::MatrixXd>& u) const;
};

struct StateSpaceNoilcWeights {
  double m = 1.0, s = 0.1, w = 0.0;  // M = m I, S = s I, W = w I (w per T^2 as in the paper's D)
};

class StateSpaceNoilc {
 public:
  /// Throws InputError when the sizes disagree, N < 2, or the cost is not positive definite.
  void setup(const StateSpaceModel& model, const StateSpaceNoilcWeights& weights, int samples);
  /// u_next = argmin sum e'Me + v'Sv + (Du)'W(Du), e = e_j - P v, v = u_next - u_j; all N x J.
  void solve(const Eigen::Ref<const Eigen::MatrixXd>& u_j, const Eigen::Ref<const Eigen::MatrixXd>& e_j,
             Eigen::Ref<Eigen::MatrixXd> u_next);

  int samples() const { return samples_; }
  int inputs() const { return static_cast<int>(B_.cols()); }
  /// Stages with gains of their own (the rest share the settled gain).
  int stored_stages() const { return tail_stages_ + 2; }
  std::size_t memory_bytes() const;

 private:
  struct Stage {
    Eigen::MatrixXd gain;     // J x (n + J): K_t = [K_dx, K_vprev]
    Eigen::MatrixXd inverse;  // J x J: H_uu(t)^-1
  };
  const Stage& stage(int t) const;
  double rate_weight(int t) const;  // 0 at t = 0, doubled at t = N-1
  /// One stage of the backward sweep: the gains of stage t from P = P_{t+1}, then P becomes P_t.
  void sweep(int t, Stage& out);

  Eigen::MatrixXd A_, B_, C_, output_to_state_;  // output_to_state_ = m C'
  Eigen::SparseMatrix<double> A_sparse_, B_sparse_;
  double m_ = 0.0, s_ = 0.0, rate_weight_ = 0.0;
  int samples_ = 0;
  Stage first_, settled_;
  std::vector<Stage> tail_;  // stages N-1, N-2, ... until the gains settled (tail_[k] is stage N-1-k)
  int tail_stages_ = 0;      // how many of tail_ this set-up filled (the rest is kept storage)
  // The sweep's workspace: P_{t+1} and P_t over z = [dx; v(t-1)], and the products of a stage.
  Eigen::MatrixXd output_weight_, P_, next_P_, PB_, curvature_, cross_, scaled_cross_, PA_;
  Eigen::LLT<Eigen::MatrixXd> factor_;
  Eigen::MatrixXd feedforward_;  // J x N, rewritten each solve
  Eigen::VectorXd p_x_, next_x_, dx_, next_dx_;
  Eigen::VectorXd p_v_, h_, rate_, change_, previous_change_;
};

}  // namespace bellows
