#include "engine/learning/noilc_state_space.hpp"

#include <cmath>
#include <string>

#include "engine/base/errors.hpp"

namespace bellows {
namespace {
// Gains that change by less than this (relative to their size) from one stage to the next have
// settled: the remaining stages of a time-invariant problem repeat them to rounding.
constexpr double kSettledGain = 1e-13;

using Sparse = Eigen::SparseMatrix<double>;

// The sweep's products, on the raw storage of column-major matrices (rows x cols, leading dimension
// ld) and of compressed-column sparse ones: each a loop the compiler vectorizes, none of Eigen's
// general product machinery (packing, blocking) that costs more than the arithmetic at these sizes.

/// out = X S: column j of out is the combination of X's columns that S's column j names.
void times_sparse(const double* X, Eigen::Index rows, Eigen::Index ldx, const Sparse& S, double* out,
                  Eigen::Index ldo) {
  const int* outer = S.outerIndexPtr();
  const int* inner = S.innerIndexPtr();
  const double* values = S.valuePtr();
  for (Eigen::Index j = 0; j < S.outerSize(); ++j) {
    double* o = out + j * ldo;
    for (Eigen::Index r = 0; r < rows; ++r) o[r] = 0.0;
    for (int k = outer[j]; k < outer[j + 1]; ++k) {
      const double a = values[k];
      const double* x = X + static_cast<Eigen::Index>(inner[k]) * ldx;
      for (Eigen::Index r = 0; r < rows; ++r) o[r] += a * x[r];
    }
  }
}

/// Column j of S dotted with x (S' x, one entry).
double column_dot(const Sparse& S, Eigen::Index j, const double* x) {
  const int* inner = S.innerIndexPtr();
  const double* values = S.valuePtr();
  double sum = 0.0;
  for (int k = S.outerIndexPtr()[j]; k < S.outerIndexPtr()[j + 1]; ++k) sum += values[k] * x[inner[k]];
  return sum;
}

/// out = S' x.
void transpose_times(const Sparse& S, const Eigen::Ref<const Eigen::VectorXd>& x, Eigen::Ref<Eigen::VectorXd> out) {
  for (Eigen::Index j = 0; j < S.outerSize(); ++j) out(j) = column_dot(S, j, x.data());
}

/// out = S x.
void times(const Sparse& S, const Eigen::Ref<const Eigen::VectorXd>& x, Eigen::Ref<Eigen::VectorXd> out) {
  out.setZero();
  const int* inner = S.innerIndexPtr();
  const double* values = S.valuePtr();
  for (Eigen::Index j = 0; j < S.outerSize(); ++j) {
    const double xj = x(j);
    for (int k = S.outerIndexPtr()[j]; k < S.outerIndexPtr()[j + 1]; ++k) out(inner[k]) += values[k] * xj;
  }
}

/// The upper triangle from the lower: exactly symmetric.
void mirror_lower(Eigen::MatrixXd& M) { M.triangularView<Eigen::StrictlyUpper>() = M.transpose(); }
}  // namespace

Eigen::MatrixXd StateSpaceModel::simulate(const Eigen::Ref<const Eigen::MatrixXd>& u) const {
  const Sparse A_sparse = A.sparseView();
  Eigen::MatrixXd y(u.rows(), u.cols());
  Eigen::VectorXd x = Eigen::VectorXd::Zero(A.rows()), next(A.rows());
  for (Eigen::Index t = 0; t < u.rows(); ++t) {
    times(A_sparse, x, next);
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
  A_sparse_ = A_.sparseView();
  B_sparse_ = B_.sparseView();
  m_ = weights.m;
  s_ = weights.s;
  rate_weight_ = weights.w / (model.sample_time_s * model.sample_time_s);
  samples_ = samples;
  output_to_state_ = m_ * C_.transpose();
  // Augmented model z = [dx; v(t-1)]: Ab = [[A, 0], [0, 0]], Bb = [B; I], Cb = [C, 0] (noilc_mimo).
  const Eigen::Index augmented = n + J;
  output_weight_.setZero(augmented, augmented);
  output_weight_.topLeftCorner(n, n).noalias() = output_to_state_ * C_;  // m Cb' Cb
  P_ = output_weight_;                                                   // P_N
  next_P_.resize(augmented, augmented);
  PB_.resize(augmented, J);
  curvature_.resize(J, J);
  cross_.resize(augmented, J);
  scaled_cross_.resize(augmented, J);
  PA_.resize(n, n);
  tail_stages_ = 0;
  bool settled = false;
  for (int t = samples - 1; t >= 1; --t) {
    if (static_cast<std::size_t>(tail_stages_) == tail_.size()) tail_.emplace_back();
    Stage& stage = tail_[static_cast<std::size_t>(tail_stages_)];
    sweep(t, stage);
    if (tail_stages_ > 0) {
      const Stage& last = tail_[static_cast<std::size_t>(tail_stages_) - 1];
      const double size = 1.0 + stage.gain.cwiseAbs().maxCoeff();
      if ((stage.gain - last.gain).cwiseAbs().maxCoeff() <= kSettledGain * size &&
          (stage.inverse - last.inverse).cwiseAbs().maxCoeff() <=
              kSettledGain * (1.0 + stage.inverse.cwiseAbs().maxCoeff())) {
        settled_ = stage;
        settled = true;
        break;
      }
    }
    ++tail_stages_;
  }
  if (!settled) settled_ = tail_[static_cast<std::size_t>(tail_stages_) - 1];
  sweep(0, first_);  // from the settled P: every stage between repeats the settled one
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

void StateSpaceNoilc::sweep(int t, Stage& out) {
  const Eigen::Index n = A_.rows(), J = B_.cols(), augmented = n + J;
  const double W = rate_weight(t);
  // PB = P Bb = P_{:,x} B + P_{:,v}; the curvature Bb' P Bb + S + W (symmetric, J x J).
  times_sparse(P_.data(), augmented, augmented, B_sparse_, PB_.data(), augmented);
  PB_ += P_.rightCols(J);
  for (Eigen::Index k = 0; k < J; ++k) {
    for (Eigen::Index l = 0; l < J; ++l) curvature_(k, l) = column_dot(B_sparse_, k, PB_.col(l).data()) + PB_(n + k, l);
  }
  curvature_.diagonal().array() += s_ + W;
  for (Eigen::Index i = 0; i < J; ++i) {
    for (Eigen::Index k = 0; k < i; ++k)
      curvature_(i, k) = curvature_(k, i) = 0.5 * (curvature_(i, k) + curvature_(k, i));
  }
  // Ab = [[A, 0], [0, 0]]: cross = PB' Ab - [0, W I] = [PB_x' A, -W I] (held transposed, (n + J) x J)
  // and Ab' P Ab = [[A' P_xx A, 0], [0, 0]].
  for (Eigen::Index k = 0; k < J; ++k) {
    for (Eigen::Index j = 0; j < n; ++j) cross_(j, k) = column_dot(A_sparse_, j, PB_.col(k).data());
  }
  cross_.bottomRows(J).setZero();
  cross_.bottomRows(J).diagonal().array() -= W;
  factor_.compute(curvature_);
  if (factor_.info() != Eigen::Success || !curvature_.allFinite()) {
    throw InputError("norm-optimal ILC: the weights do not give a positive definite cost (need s + w > 0 or m > 0)");
  }
  out.inverse.setIdentity(J, J);
  factor_.solveInPlace(out.inverse);
  // scaled_cross = cross' H^-1 ((n + J) x J): the gain is its transpose, negated, and P's downdate
  // cross' H^-1 cross its product with cross.
  scaled_cross_.setZero();
  for (Eigen::Index k = 0; k < J; ++k) {
    for (Eigen::Index l = 0; l < J; ++l) scaled_cross_.col(k) += out.inverse(l, k) * cross_.col(l);
  }
  out.gain = -scaled_cross_.transpose();
  // P_t = Q + Ab' P Ab - cross' H^-1 cross, Q = m Cb' Cb (none at t = 0) plus W on v(t-1); the lower
  // triangle, then mirrored.
  if (t >= 1) next_P_ = output_weight_;
  else next_P_.setZero();
  next_P_.bottomRightCorner(J, J).diagonal().array() += W;
  times_sparse(P_.data(), n, augmented, A_sparse_, PA_.data(), n);  // P_xx A
  for (Eigen::Index j = 0; j < n; ++j) {                            // (A' P_xx A)(r, j) = A(:, r)' (P_xx A)(:, j)
    const double* pa = PA_.col(j).data();
    double* column = next_P_.col(j).data();
    for (Eigen::Index r = j; r < n; ++r) column[r] += column_dot(A_sparse_, r, pa);
  }
  for (Eigen::Index j = 0; j < augmented; ++j) {
    double* column = next_P_.col(j).data();
    for (Eigen::Index k = 0; k < J; ++k) {
      const double c = scaled_cross_(j, k);
      const double* x = cross_.col(k).data();
      for (Eigen::Index r = j; r < augmented; ++r) column[r] -= c * x[r];
    }
  }
  mirror_lower(next_P_);
  P_.swap(next_P_);
}

double StateSpaceNoilc::rate_weight(int t) const {
  if (t == 0) return 0.0;  // D's rows as noilc_riccati: u(0) has no change of its own, the last one counts twice
  return t == samples_ - 1 ? 2.0 * rate_weight_ : rate_weight_;
}

const StateSpaceNoilc::Stage& StateSpaceNoilc::stage(int t) const {
  if (t == 0) return first_;
  const auto from_end = static_cast<std::size_t>(samples_ - 1 - t);
  return from_end < static_cast<std::size_t>(tail_stages_) ? tail_[from_end] : settled_;
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
    transpose_times(A_sparse_, p_x_, next_x_);
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
    times(A_sparse_, dx_, next_dx_);
    next_dx_.noalias() += B_ * change_;
    dx_.swap(next_dx_);
    previous_change_ = change_;
  }
}

std::size_t StateSpaceNoilc::memory_bytes() const {
  const auto per_stage = static_cast<std::size_t>(first_.gain.size() + first_.inverse.size());
  // The tail's storage beyond tail_stages_ (kept from an earlier, longer sweep) is held too.
  return sizeof(double) * (per_stage * (tail_.size() + 2) + static_cast<std::size_t>(feedforward_.size()));
}

}  // namespace bellows
