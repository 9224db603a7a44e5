#include "engine/learning/noilc_mimo.hpp"

#include <vector>

namespace bellows {

MultiJointWeights MultiJointWeights::uniform(const IlcParameters& weights, int joints) {
  MultiJointWeights result;
  result.m = weights.m * JointMatrix::Identity(joints, joints);
  result.s = weights.s * JointMatrix::Identity(joints, joints);
  result.w = weights.w * JointMatrix::Identity(joints, joints);
  return result;
}

MultiJointWeights MultiJointWeights::per_joint(std::span<const IlcParameters> per_joint) {
  const auto joints = static_cast<Eigen::Index>(per_joint.size());
  MultiJointWeights result;
  result.m.setZero(joints, joints);
  result.s.setZero(joints, joints);
  result.w.setZero(joints, joints);
  for (Eigen::Index i = 0; i < joints; ++i) {
    result.m(i, i) = per_joint[static_cast<std::size_t>(i)].m;
    result.s(i, i) = per_joint[static_cast<std::size_t>(i)].s;
    result.w(i, i) = per_joint[static_cast<std::size_t>(i)].w;
  }
  return result;
}

const char* to_string(MultiJointNoilcStatus status) {
  switch (status) {
    case MultiJointNoilcStatus::kOk:
      return "ok";
    case MultiJointNoilcStatus::kNotSetUp:
      return "not set up";
    case MultiJointNoilcStatus::kBadJointCount:
      return "the joint count must be 1 to 4";
    case MultiJointNoilcStatus::kTooFewSamples:
      return "norm-optimal ILC needs at least 2 samples";
    case MultiJointNoilcStatus::kBadModel:
      return "the model is not 2J x 2J, 2J x J, J x 2J and finite with T > 0";
    case MultiJointNoilcStatus::kBadWeights:
      return "the weights m, s, w must be symmetric positive semidefinite J x J matrices and rho >= 0";
    case MultiJointNoilcStatus::kNotPositiveDefinite:
      return "the weights do not give a positive definite cost";
    case MultiJointNoilcStatus::kShapeMismatch:
      return "the data are not N x J";
    case MultiJointNoilcStatus::kNonFiniteData:
      return "the data hold a NaN or an infinity";
    case MultiJointNoilcStatus::kBadBounds:
      return "the bounds are not N x J or a lower bound exceeds its upper bound";
    case MultiJointNoilcStatus::kNotConverged:
      return "the bounded update did not converge within its iterations";
  }
  return "unknown";
}

class MultiJointNoilc::Stages {
 public:
  virtual ~Stages() = default;
  virtual void solve(const Eigen::Ref<const Eigen::MatrixXd>& u_j, const Eigen::Ref<const Eigen::MatrixXd>& e_j,
                     const Eigen::Ref<const Eigen::MatrixXd>& target, Eigen::Ref<Eigen::MatrixXd> u_next) = 0;
  virtual std::size_t memory_bytes() const = 0;
};

namespace {

/// The Riccati recursion of the set-up, backwards from P_N: each stage's gain K_t and the inverse of
/// its curvature H_uu(t). Dynamic sizes and not a template: it runs once per set-up (which may
/// allocate), and four fixed-size copies of it (J = 1..4, matrices up to 12 x 12) took GCC two
/// minutes at -O3. The per-iteration sweeps of solve() stay fixed-size.
MultiJointNoilcStatus riccati_stages(const Eigen::MatrixXd& A, const Eigen::MatrixXd& B, const Eigen::MatrixXd& C,
                                     const Eigen::MatrixXd& m, const Eigen::MatrixXd& s,
                                     const Eigen::MatrixXd& rate_weight, int samples,
                                     std::vector<Eigen::MatrixXd>& gains, std::vector<Eigen::MatrixXd>& inverses) {
  using Dynamic = Eigen::MatrixXd;
  const Eigen::Index J = B.cols(), states = A.rows(), augmented = states + J;  // z = [dx; v(t-1)]
  gains.assign(static_cast<std::size_t>(samples), Dynamic());
  inverses.assign(static_cast<std::size_t>(samples), Dynamic());
  // Augmented model: Ab = [[A, 0], [0, 0]], Bb = [B; I], Cb = [C, 0].
  Dynamic Ab = Dynamic::Zero(augmented, augmented);
  Ab.topLeftCorner(states, states) = A;
  Dynamic Bb(augmented, J);
  Bb << B, Dynamic::Identity(J, J);
  Dynamic Cb = Dynamic::Zero(J, augmented);
  Cb.leftCols(states) = C;
  const Dynamic output_weight = Cb.transpose() * m * Cb;
  Dynamic P = output_weight;  // P_N
  for (int t = samples - 1; t >= 0; --t) {
    // As FixedStages::rate_weight: none at t = 0, twice at t = N-1.
    const Dynamic W = t == 0 ? Dynamic::Zero(J, J) : Dynamic(t == samples - 1 ? 2.0 * rate_weight : rate_weight);
    Dynamic Q = t >= 1 ? output_weight : Dynamic::Zero(augmented, augmented);
    Q.bottomRightCorner(J, J) += W;
    const Dynamic PB = P * Bb;
    Dynamic curvature = s + W + Bb.transpose() * PB;  // H_uu
    curvature = (0.5 * (curvature + curvature.transpose())).eval();
    Dynamic cross = PB.transpose() * Ab;  // H_ux = N' + Bb' P Ab with N = [0; -W]
    cross.rightCols(J) -= W;
    const Eigen::LLT<Dynamic> factor(curvature);
    if (factor.info() != Eigen::Success || !curvature.allFinite()) return MultiJointNoilcStatus::kNotPositiveDefinite;
    const Dynamic inverse = factor.solve(Dynamic::Identity(J, J));
    gains[static_cast<std::size_t>(t)] = -inverse * cross;
    inverses[static_cast<std::size_t>(t)] = inverse;
    P = Q + Ab.transpose() * P * Ab - cross.transpose() * inverse * cross;
    P = (0.5 * (P + P.transpose())).eval();
  }
  return MultiJointNoilcStatus::kOk;
}

/// The sweeps for exactly J joints: fixed-size stage matrices, so that the compiler unrolls them.
template <int J>
class FixedStages final : public MultiJointNoilc::Stages {
  static constexpr int kStates = 2 * J;
  static constexpr int kAugmented = kStates + J;  // z = [dx; v(t-1)]
  using JJ = Eigen::Matrix<double, J, J>;
  using JVec = Eigen::Matrix<double, J, 1>;
  using XVec = Eigen::Matrix<double, kStates, 1>;
  using Aug = Eigen::Matrix<double, kAugmented, kAugmented>;
  using Gain = Eigen::Matrix<double, J, kAugmented>;

 public:
  /// Allocates the stages; the status says whether every stage's curvature is positive definite.
  MultiJointNoilcStatus setup(const MultiJointModel& model, const MultiJointWeights& weights, int samples, double rho) {
    A_ = model.A;
    B_ = model.B;
    C_ = model.C;
    m_ = weights.m;
    output_to_state_ = C_.transpose() * m_;  // C'M
    rate_weight_ = weights.w / (model.sample_time_s * model.sample_time_s);
    rho_ = rho;
    samples_ = samples;
    gains_.resize(static_cast<std::size_t>(samples));
    inverse_curvature_.resize(static_cast<std::size_t>(samples));
    feedforward_.resize(static_cast<std::size_t>(samples));
    std::vector<Eigen::MatrixXd> gains, inverses;
    const MultiJointNoilcStatus status =
        riccati_stages(A_, B_, C_, m_, weights.s + rho * JJ::Identity(), rate_weight_, samples, gains, inverses);
    if (status != MultiJointNoilcStatus::kOk) return status;
    for (std::size_t t = 0; t < gains.size(); ++t) {
      gains_[t] = gains[t];
      inverse_curvature_[t] = inverses[t];
    }
    return MultiJointNoilcStatus::kOk;
  }

  void solve(const Eigen::Ref<const Eigen::MatrixXd>& u_j, const Eigen::Ref<const Eigen::MatrixXd>& e_j,
             const Eigen::Ref<const Eigen::MatrixXd>& target, Eigen::Ref<Eigen::MatrixXd> u_next) override {
    const int n = samples_;
    const bool proximal = rho_ > 0.0;
    // Backward pass for the affine terms p = [p_x; p_v], from p_N = -C'M e(N). Row t-1 of e_j is sample t.
    XVec p_x = -output_to_state_ * e_j.row(n - 1).transpose();
    JVec p_v = JVec::Zero();
    for (int t = n - 1; t >= 0; --t) {
      const auto stage = static_cast<std::size_t>(t);
      const JJ W = rate_weight(t);
      JVec rate = JVec::Zero();
      if (t >= 1) rate = (u_j.row(t) - u_j.row(t - 1)).transpose();
      JVec r = W * rate;
      if (proximal) r -= rho_ * (target.row(t) - u_j.row(t)).transpose();
      const JVec h = r + B_.transpose() * p_x + p_v;
      feedforward_[stage] = -inverse_curvature_[stage] * h;
      const Gain& K = gains_[stage];
      XVec next_x = A_.transpose() * p_x + K.template leftCols<kStates>().transpose() * h;
      if (t >= 1) next_x -= output_to_state_ * e_j.row(t - 1).transpose();
      p_x = next_x;
      p_v = -W * rate + K.template rightCols<J>().transpose() * h;
    }
    // Forward pass: v(t) = K_t z(t) + k_t.
    XVec dx = XVec::Zero();
    JVec previous_change = JVec::Zero();
    for (int t = 0; t < n; ++t) {
      const auto stage = static_cast<std::size_t>(t);
      const Gain& K = gains_[stage];
      const JVec change =
          K.template leftCols<kStates>() * dx + K.template rightCols<J>() * previous_change + feedforward_[stage];
      u_next.row(t) = u_j.row(t) + change.transpose();
      dx = A_ * dx + B_ * change;
      previous_change = change;
    }
  }

  std::size_t memory_bytes() const override {
    return static_cast<std::size_t>(samples_) * (sizeof(Gain) + sizeof(JJ) + sizeof(JVec));
  }

 private:
  JJ rate_weight(int t) const {
    // D's rows are (u(t+1) - u(t)) / T for t = 0..N-2 and the last row repeats the one before: the
    // change at t = N-1 counts twice, and u(0) has no change of its own.
    if (t == 0) return JJ::Zero();
    return t == samples_ - 1 ? JJ(2.0 * rate_weight_) : rate_weight_;
  }

  Eigen::Matrix<double, kStates, kStates> A_;
  Eigen::Matrix<double, kStates, J> B_;
  Eigen::Matrix<double, J, kStates> C_;
  JJ m_, rate_weight_;
  Eigen::Matrix<double, kStates, J> output_to_state_;
  double rho_ = 0.0;
  int samples_ = 0;
  std::vector<Gain> gains_;            // K_t
  std::vector<JJ> inverse_curvature_;  // H_uu(t)^-1
  std::vector<JVec> feedforward_;      // k_t, rewritten each solve
};

template <int J>
MultiJointNoilcStatus make_stages(const MultiJointModel& model, const MultiJointWeights& weights, int samples,
                                  double rho, std::unique_ptr<MultiJointNoilc::Stages>& out) {
  auto stages = std::make_unique<FixedStages<J>>();
  const MultiJointNoilcStatus status = stages->setup(model, weights, samples, rho);
  if (status == MultiJointNoilcStatus::kOk) out = std::move(stages);
  return status;
}

/// Symmetric with no eigenvalue below -1e-12 * scale: then, and only then, the weight shifted up by
/// that tolerance is positive definite, which its Cholesky factor tells. The same LLT<MatrixXd> as
/// riccati_stages: an eigensolver for the test cost 12 s of GCC's time on this file (docs/benchmarks.md).
bool symmetric_positive_semidefinite(const JointMatrix& weight, int joints) {
  if (weight.rows() != joints || weight.cols() != joints || !weight.allFinite()) return false;
  const double scale = 1.0 + weight.cwiseAbs().maxCoeff();
  if (!(weight - weight.transpose()).isZero(1e-12 * scale)) return false;
  const Eigen::MatrixXd shifted = weight + 1e-12 * scale * Eigen::MatrixXd::Identity(joints, joints);
  return Eigen::LLT<Eigen::MatrixXd>(shifted).info() == Eigen::Success;
}

}  // namespace

MultiJointNoilc::MultiJointNoilc() = default;
MultiJointNoilc::~MultiJointNoilc() = default;
MultiJointNoilc::MultiJointNoilc(MultiJointNoilc&&) noexcept = default;
MultiJointNoilc& MultiJointNoilc::operator=(MultiJointNoilc&&) noexcept = default;

MultiJointNoilcStatus MultiJointNoilc::setup(const MultiJointModel& model, const MultiJointWeights& weights,
                                             int samples, double proximal_weight) {
  stages_.reset();
  info_ = MultiJointNoilcInfo{};
  const int J = model.joints();
  auto fail = [&](MultiJointNoilcStatus status) { return info_.status = status; };
  if (J < 1 || J > kMaxJoints) return fail(MultiJointNoilcStatus::kBadJointCount);
  if (samples < 2) return fail(MultiJointNoilcStatus::kTooFewSamples);
  if (model.A.rows() != 2 * J || model.A.cols() != 2 * J || model.B.rows() != 2 * J || model.B.cols() != J ||
      model.C.cols() != 2 * J || !model.A.allFinite() || !model.B.allFinite() || !model.C.allFinite() ||
      !(model.sample_time_s > 0.0)) {
    return fail(MultiJointNoilcStatus::kBadModel);
  }
  if (!symmetric_positive_semidefinite(weights.m, J) || !symmetric_positive_semidefinite(weights.s, J) ||
      !symmetric_positive_semidefinite(weights.w, J) || !(proximal_weight >= 0.0)) {
    return fail(MultiJointNoilcStatus::kBadWeights);
  }
  MultiJointNoilcStatus status = MultiJointNoilcStatus::kBadJointCount;
  switch (J) {
    case 1:
      status = make_stages<1>(model, weights, samples, proximal_weight, stages_);
      break;
    case 2:
      status = make_stages<2>(model, weights, samples, proximal_weight, stages_);
      break;
    case 3:
      status = make_stages<3>(model, weights, samples, proximal_weight, stages_);
      break;
    case 4:
      status = make_stages<4>(model, weights, samples, proximal_weight, stages_);
      break;
    default:
      break;
  }
  if (status != MultiJointNoilcStatus::kOk) return fail(status);
  info_.status = status;
  info_.joints = J;
  info_.samples = samples;
  info_.proximal_weight = proximal_weight;
  info_.memory_bytes = stages_->memory_bytes();
  return status;
}

MultiJointNoilcStatus MultiJointNoilc::solve(const Eigen::Ref<const Eigen::MatrixXd>& u_j,
                                             const Eigen::Ref<const Eigen::MatrixXd>& e_j,
                                             const Eigen::Ref<const Eigen::MatrixXd>& target,
                                             Eigen::Ref<Eigen::MatrixXd> u_next) {
  if (!stages_) return info_.status = MultiJointNoilcStatus::kNotSetUp;
  const Eigen::Index n = info_.samples, J = info_.joints;
  const bool proximal = info_.proximal_weight > 0.0;
  auto shaped = [&](Eigen::Index rows, Eigen::Index cols) { return rows == n && cols == J; };
  if (!shaped(u_j.rows(), u_j.cols()) || !shaped(e_j.rows(), e_j.cols()) || !shaped(u_next.rows(), u_next.cols()) ||
      (proximal && !shaped(target.rows(), target.cols()))) {
    return info_.status = MultiJointNoilcStatus::kShapeMismatch;
  }
  if (!u_j.allFinite() || !e_j.allFinite() || (proximal && !target.allFinite())) {
    return info_.status = MultiJointNoilcStatus::kNonFiniteData;
  }
  stages_->solve(u_j, e_j, target, u_next);
  ++info_.solves;
  return info_.status = MultiJointNoilcStatus::kOk;
}

}  // namespace bellows
