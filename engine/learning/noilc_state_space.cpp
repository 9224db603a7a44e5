#include "engine/learning/noilc_state_space.hpp"

#include <cmath>
#include <string>
#include <utility>

#include <Eigen/SparseCore>

#include "engine/base/errors.hpp"

namespace bellows {
namespace {
// Gains that change by less than this (relative to their size) from one stage to the next have
// settled: the remaining stages of a time-invariant problem repeat them to rounding.
constexpr double kSettledGain = 1e-13;
}  // namespace

Eigen::MatrixXd StateSpaceModel::simulate(const Eigen::Ref<const Eigen::MatrixXd>& u) const {
  Eigen::MatrixXd y(u.rows(), u.cols());
  Eigen::VectorXd x = Eigen::VectorXd::Zero(A.rows()), next(A.rows());
  for (Eigen::Index t = 0; t < u.rows(); ++t) {
    next.noalias() = A * x;
    next.noalias() += B * u.row(t).transpose();
    x.swap(next);
    y.row(t).noalias() = (C * x).transpose();
  }
  return y;
}

void StateSpaceNoilc::setup(const StateSpaceModel& model, const StateSpaceNoilcWeights& weights, int samples) {
  const Eigen::Index n = model.A.rows(), J = model.B.cols();
  if (model.A.cols() != n || model.B.rows() != n || model.C.rows() != J || model.C.cols() != n || J < 1) {
    throw InputError("norm-optimal ILC: the model's A, B, C do not fit together");
  }
  if (!model.A.allFinite() || !model.B.allFinite() || !model.C.allFinite() || !(model.sample_time_s > 0.0)) {
    throw InputError("norm-optimal ILC: the model is not finite");
  }
  if (samples < 2) throw InputError("norm-optimal ILC needs at least 2 samples, got " + std::to_string(samples));
  if (!(weights.m >= 0.0) || !(weights.s >= 0.0) || !(weights.w >= 0.0)) {
    throw InputError("norm-optimal ILC: the weights m, s, w must not be negative");
  }
  A_ = model.A;
  B_ = model.B;
  C_ = model.C;
  m_ = weights.m;
  s_ = weights.s;
  rate_weight_ = weights.w / (model.sample_time_s * model.sample_time_s);
  samples_ = samples;
  output_to_state_ = m_ * C_.transpose();
  // Augmented model z = [dx; v(t-1)]: Ab = [[A, 0], [0, 0]], Bb = [B; I], Cb = [C, 0] (noilc_mimo).
  const Eigen::Index augmented = n + J;
  Eigen::MatrixXd Bb(augmented, J);
  Bb << B_, Eigen::MatrixXd::Identity(J, J);
  Eigen::MatrixXd Cb = Eigen::MatrixXd::Zero(J, augmented);
  Cb.leftCols(n) = C_;
  const Eigen::MatrixXd output_weight = m_ * Cb.transpose() * Cb;
  // A is sparse (the closed loop's blocks, the correction's shift register and low-passes): the
  // sweep's products with it cost O(nonzeros x n) instead of O(n^3), which is what keeps a refit's
  // set-up within the time between trials for J joints.
  const Eigen::SparseMatrix<double> A_sparse = A_.sparseView();
  Eigen::MatrixXd P = output_weight;  // P_N
  tail_.clear();
  bool settled = false;
  auto sweep = [&](int t) {
    const double W = rate_weight(t);
    Eigen::MatrixXd Q = t >= 1 ? output_weight : Eigen::MatrixXd::Zero(augmented, augmented);
    Q.bottomRightCorner(J, J).diagonal().array() += W;
    const Eigen::MatrixXd PB = P * Bb;
    Eigen::MatrixXd curvature = Bb.transpose() * PB;
    curvature.diagonal().array() += s_ + W;
    curvature = (0.5 * (curvature + curvature.transpose())).eval();
    // Ab = [[A, 0], [0, 0]]: cross = PB' Ab = [PB_x' A, 0] and Ab' P Ab = [[A' P_xx A, 0], [0, 0]].
    Eigen::MatrixXd cross = Eigen::MatrixXd::Zero(J, augmented);
    cross.leftCols(n) = PB.topRows(n).transpose() * A_sparse;
    cross.rightCols(J).diagonal().array() -= W;
    const Eigen::LLT<Eigen::MatrixXd> factor(curvature);
    if (factor.info() != Eigen::Success || !curvature.allFinite()) {
      throw InputError("norm-optimal ILC: the weights do not give a positive definite cost (need s + w > 0 or m > 0)");
    }
    Stage stage;
    stage.inverse = factor.solve(Eigen::MatrixXd::Identity(J, J));
    stage.gain = -stage.inverse * cross;
    const Eigen::MatrixXd PA = P.topLeftCorner(n, n) * A_sparse;
    Eigen::MatrixXd next = Q - cross.transpose() * stage.inverse * cross;
    next.topLeftCorner(n, n) += A_sparse.transpose() * PA;
    P = std::move(next);
    P = (0.5 * (P + P.transpose())).eval();
    return stage;
  };
  for (int t = samples - 1; t >= 1; --t) {
    Stage stage = sweep(t);
    if (t < samples - 1 && !tail_.empty()) {
      const double size = 1.0 + stage.gain.cwiseAbs().maxCoeff();
      if ((stage.gain - tail_.back().gain).cwiseAbs().maxCoeff() <= kSettledGain * size &&
          (stage.inverse - tail_.back().inverse).cwiseAbs().maxCoeff() <=
              kSettledGain * (1.0 + stage.inverse.cwiseAbs().maxCoeff())) {
        settled_ = std::move(stage);
        settled = true;
        break;
      }
    }
    tail_.push_back(std::move(stage));
  }
  if (!settled) settled_ = tail_.back();
  first_ = sweep(0);  // from the settled P: every stage between repeats the settled one
  feedforward_.resize(J, samples);
  p_x_.resize(n);
  next_x_.resize(n);
  dx_.resize(n);
  next_dx_.resize(n);
  p_v_.resize(J);
  h_.resize(J);
  rate_.resize(J);
  change_.resize(J);
  previous_change_.resize(J);
}

double StateSpaceNoilc::rate_weight(int t) const {
  if (t == 0) return 0.0;  // D's rows as noilc_riccati: u(0) has no change of its own, the last one counts twice
  return t == samples_ - 1 ? 2.0 * rate_weight_ : rate_weight_;
}

const StateSpaceNoilc::Stage& StateSpaceNoilc::stage(int t) const {
  if (t == 0) return first_;
  const auto from_end = static_cast<std::size_t>(samples_ - 1 - t);
  return from_end < tail_.size() ? tail_[from_end] : settled_;
}

void StateSpaceNoilc::solve(const Eigen::Ref<const Eigen::MatrixXd>& u_j, const Eigen::Ref<const Eigen::MatrixXd>& e_j,
                            Eigen::Ref<Eigen::MatrixXd> u_next) {
  const int N = samples_;
  const Eigen::Index n = A_.rows(), J = B_.cols();
  if (u_j.rows() != N || e_j.rows() != N || u_next.rows() != N || u_j.cols() != J || e_j.cols() != J ||
      u_next.cols() != J) {
    throw InputError("norm-optimal ILC: the data are not " + std::to_string(N) + " x " + std::to_string(J));
  }
  // Backward pass for the affine terms p = [p_x; p_v], from p_N = -m C' e(N). Row t-1 of e_j is sample t.
  p_x_.noalias() = output_to_state_ * e_j.row(N - 1).transpose();
  p_x_ = -p_x_;
  p_v_.setZero();
  for (int t = N - 1; t >= 0; --t) {
    const double W = rate_weight(t);
    if (t >= 1) {
      rate_ = (u_j.row(t) - u_j.row(t - 1)).transpose();
    } else {
      rate_.setZero();
    }
    h_.noalias() = B_.transpose() * p_x_;
    h_ += W * rate_ + p_v_;
    const Stage& K = stage(t);
    feedforward_.col(t).noalias() = K.inverse * h_;
    feedforward_.col(t) = -feedforward_.col(t);
    next_x_.noalias() = A_.transpose() * p_x_;
    next_x_.noalias() += K.gain.leftCols(n).transpose() * h_;
    if (t >= 1) next_x_.noalias() -= output_to_state_ * e_j.row(t - 1).transpose();
    p_x_.swap(next_x_);
    p_v_.noalias() = K.gain.rightCols(J).transpose() * h_;
    p_v_ -= W * rate_;
  }
  // Forward pass: v(t) = K_t z(t) + k_t.
  dx_.setZero();
  previous_change_.setZero();
  for (int t = 0; t < N; ++t) {
    const Stage& K = stage(t);
    change_ = feedforward_.col(t);
    change_.noalias() += K.gain.leftCols(n) * dx_;
    change_.noalias() += K.gain.rightCols(J) * previous_change_;
    u_next.row(t) = u_j.row(t) + change_.transpose();
    next_dx_.noalias() = A_ * dx_;
    next_dx_.noalias() += B_ * change_;
    dx_.swap(next_dx_);
    previous_change_ = change_;
  }
}

std::size_t StateSpaceNoilc::memory_bytes() const {
  const auto per_stage = static_cast<std::size_t>(first_.gain.size() + first_.inverse.size());
  return sizeof(double) *
         (per_stage * static_cast<std::size_t>(stored_stages()) + static_cast<std::size_t>(feedforward_.size()));
}

}  // namespace bellows
