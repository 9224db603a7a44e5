// The chain's equations (engine/model/arm_chain.hpp) for exactly J joints, with fixed-size matrices so that
// the compiler unrolls them: the integrators' right-hand side runs ~45 000 times per simulated second.
// Used by ArmChain (mechanics alone) and PneumaticArmChain (with each joint's bellows); ArmChain's
// interface is the place to read what the terms mean.
//
// Speed (docs/benchmarks.md, "Several joints"): the sines and cosines of the links' absolute angles
// are carried from stage to stage and step to step by the angle-addition formulas with a short series
// for the small increment (Trig::advanced), exact std::sin/std::cos only every kTrigRefreshSteps
// steps; M(q) comes from the tip's composite bodies and C q_dot + G from one recursive Newton-Euler
// pass, each link's point masses and inertia entering as three moments (mass, first, second); the
// J x J solve is by the adjugate up to J = 3. The loops over joints are unrolled explicitly: left
// to itself GCC kept an earlier rigid-body sweep's nested loops rolled, at 8x the time.
#pragma once

#include <array>
#include <cmath>
#include <numbers>

#include <Eigen/Dense>

#include "engine/model/arm_chain_parameters.hpp"

namespace bellows::arm_chain_kernel {

/// Steps between exact evaluations of the links' sines and cosines (the rotations in between drift
/// by about one rounding error per step).
inline constexpr int kTrigRefreshSteps = 50;

/// sin and cos of the links' absolute angles theta_k = q_1 + ... + q_k.
template <int J>
struct Trig {
  std::array<double, J> sin{}, cos{};

  static Trig exact(const Eigen::Matrix<double, J, 1>& q) {
    Trig t;
    double theta = 0.0;
    for (int k = 0; k < J; ++k) {
      theta += q(k);
      t.sin[k] = std::sin(theta);
      t.cos[k] = std::cos(theta);
    }
    return t;
  }

  /// The same at q + dq, from these values: sin(theta + d) = sin theta cos d + cos theta sin d with
  /// sin d and cos d - 1 from their series, exact to rounding for |d| <= 0.005 rad (the increment of
  /// a 0.1 ms step at up to 50 rad/s; the terms left out are below 1e-16 relative). Larger increments
  /// take the exact path at `q_new`.
  Trig advanced(const Eigen::Matrix<double, J, 1>& dq, const Eigen::Matrix<double, J, 1>& q_new) const {
    Trig t;
    double d = 0.0;
#pragma GCC unroll 4
    for (int k = 0; k < J; ++k) {
      d += dq(k);
      if (!(std::abs(d) <= 0.005)) return exact(q_new);
      const double d2 = d * d;
      const double sin_d = d + d * d2 * (-1.0 / 6.0 + d2 * (1.0 / 120.0));
      const double cos_d_minus_1 = d2 * (-0.5 + d2 * (1.0 / 24.0 - d2 * (1.0 / 720.0)));
      t.sin[k] = sin[k] + (sin[k] * cos_d_minus_1 + cos[k] * sin_d);
      t.cos[k] = cos[k] + (cos[k] * cos_d_minus_1 - sin[k] * sin_d);
    }
    return t;
  }
};

/// Solves M x = b for a symmetric positive definite J x J M: by the adjugate up to 3 x 3 (one
/// division, short dependency chains), LDL' beyond.
template <int J>
inline Eigen::Matrix<double, J, 1> solve_spd(const Eigen::Matrix<double, J, J>& M,
                                             const Eigen::Matrix<double, J, 1>& b) {
  if constexpr (J == 1) {
    return Eigen::Matrix<double, 1, 1>(b(0) / M(0, 0));
  } else if constexpr (J == 2) {
    const double inv_det = 1.0 / (M(0, 0) * M(1, 1) - M(1, 0) * M(1, 0));
    return Eigen::Matrix<double, 2, 1>((M(1, 1) * b(0) - M(1, 0) * b(1)) * inv_det,
                                       (M(0, 0) * b(1) - M(1, 0) * b(0)) * inv_det);
  } else if constexpr (J == 3) {
    const double m00 = M(0, 0), m01 = M(1, 0), m02 = M(2, 0), m11 = M(1, 1), m12 = M(2, 1), m22 = M(2, 2);
    const double c00 = m11 * m22 - m12 * m12, c01 = m02 * m12 - m01 * m22, c02 = m01 * m12 - m02 * m11;
    const double c11 = m00 * m22 - m02 * m02, c12 = m01 * m02 - m00 * m12, c22 = m00 * m11 - m01 * m01;
    const double inv_det = 1.0 / (m00 * c00 + m01 * c01 + m02 * c02);
    return Eigen::Matrix<double, 3, 1>((c00 * b(0) + c01 * b(1) + c02 * b(2)) * inv_det,
                                       (c01 * b(0) + c11 * b(1) + c12 * b(2)) * inv_det,
                                       (c02 * b(0) + c12 * b(1) + c22 * b(2)) * inv_det);
  }
  double L[J][J] = {}, inv_d[J] = {}, d[J] = {};
  for (int j = 0; j < J; ++j) {
    double dj = M(j, j);
    for (int k = 0; k < j; ++k) dj -= L[j][k] * L[j][k] * d[k];
    d[j] = dj;
    inv_d[j] = 1.0 / dj;
    for (int i = j + 1; i < J; ++i) {
      double lij = M(i, j);
      for (int k = 0; k < j; ++k) lij -= L[i][k] * L[j][k] * d[k];
      L[i][j] = lij * inv_d[j];
    }
  }
  Eigen::Matrix<double, J, 1> x;
  for (int i = 0; i < J; ++i) {  // L y = b
    double yi = b(i);
    for (int k = 0; k < i; ++k) yi -= L[i][k] * x(k);
    x(i) = yi;
  }
  for (int i = 0; i < J; ++i) x(i) *= inv_d[i];
  for (int i = J - 1; i >= 0; --i) {  // L' x = D^-1 y
    for (int k = i + 1; k < J; ++k) x(i) -= L[k][i] * x(k);
  }
  return x;
}

template <int J>
class Kernel {
 public:
  using Vec = Eigen::Matrix<double, J, 1>;
  using Mat = Eigen::Matrix<double, J, J>;

  /// `straight_inertia` and `damping` have J entries (zeros while ArmChain is computing them).
  Kernel(const ChainParameters& chain, const JointVector& straight_inertia, const JointVector& damping)
      : gravity_(chain.gravity ? chain.gravity_m_per_s2 : 0.0),
        stop_stiffness_(chain.hard_stop_stiffness_per_s2),
        stop_damping_(chain.hard_stop_damping_per_s) {
    for (int i = 0; i < J; ++i) {
      const ChainLink& l = chain.links[static_cast<std::size_t>(i)];
      length_[i] = l.length_m;
      // The link's centre-of-mass point, its distal point mass and its own inertia as moments of
      // the distance d from its joint: sum m, sum m d, sum m d^2 + I.
      mass_[i] = l.mass_kg + l.tip_mass_kg;
      first_moment_[i] = l.mass_kg * l.center_of_mass_m + l.tip_mass_kg * l.length_m;
      second_moment_[i] = l.mass_kg * l.center_of_mass_m * l.center_of_mass_m +
                          l.tip_mass_kg * l.length_m * l.length_m + l.inertia_kg_m2;
      stiffness_(i) = l.stiffness_Nm_per_rad;
      kappa_(i) = l.kappa_rad_per_bar;
      stiffness_kappa_(i) = l.stiffness_Nm_per_rad * l.kappa_rad_per_bar;
      damping_(i) = damping(i);
      stop_scale_(i) = straight_inertia(i);
      stop_rad_(i) = l.hard_stop_deg * std::numbers::pi / 180.0;
      creep_gain_(i) = l.creep_gain;
      creep_rate_(i) = 1.0 / l.creep_tau_s;
    }
  }

  /// M(q) from the tip's composites (composite rigid bodies): with o_i joint i's position and, for
  /// the links i..J together, Mc_i their mass, S_i their first moment about o_i (a vector) and Ic_i
  /// their inertia about o_i (own inertias included),
  ///   M_ii = Ic_i,  M_ai = Ic_i + (o_i - o_a).S_i  (a < i),
  /// since a point p on link i or beyond has the Jacobian columns z x (p - o_a). Shifting link i+1's
  /// composite to o_i by e = o_{i+1} - o_i = l_i n_i: Ic += 2 e.S + Mc l_i^2, S += Mc e; then link i
  /// adds its moments (mu0, mu1, mu2 = sum m, sum m d, sum m d^2 + I over its centre of mass and its
  /// distal point mass): S += mu1 n_i, Ic += mu2, Mc += mu0. n_k = (cos theta_k, sin theta_k).
  [[gnu::always_inline]] void mass_matrix(const Trig<J>& trig, Mat& M) const {
    double mc = 0.0, sx = 0.0, sy = 0.0, ic = 0.0;
    std::array<double, J> composite_sx{}, composite_sy{};
#pragma GCC unroll 4
    for (int i = J - 1; i >= 0; --i) {
      const double ex = length_[i] * trig.cos[i], ey = length_[i] * trig.sin[i];
      if (i < J - 1) {
        ic += 2.0 * (ex * sx + ey * sy) + mc * length_[i] * length_[i];
        sx += mc * ex;
        sy += mc * ey;
      }
      sx += first_moment_[i] * trig.cos[i];
      sy += first_moment_[i] * trig.sin[i];
      ic += second_moment_[i];
      mc += mass_[i];
      composite_sx[i] = sx;
      composite_sy[i] = sy;
      M(i, i) = ic;
    }
#pragma GCC unroll 4
    for (int i = 1; i < J; ++i) {
      double dx = 0.0, dy = 0.0;  // o_i - o_a
#pragma GCC unroll 4
      for (int a = i - 1; a >= 0; --a) {
        dx += length_[a] * trig.cos[a];
        dy += length_[a] * trig.sin[a];
        M(a, i) = M(i, i) + dx * composite_sx[i] + dy * composite_sy[i];
        M(i, a) = M(a, i);
      }
    }
  }

  /// The velocity-product and gravity torques C(q, q_dot) q_dot + G(q) (recursive Newton-Euler at zero
  /// joint acceleration): tau_a = sum over the points p beyond joint a of (p - o_a) x m_p acc_p, with
  /// acc_p the point's acceleration from the rates alone plus `gravity_m_per_s2` upward (the base
  /// accelerating upward is gravity pulling down). Forward: acc_o(i+1) = acc_o(i) - w_i^2 l_i n_i;
  /// link i's force F_i = mu0 acc_o(i) - w_i^2 mu1 n_i and moment about o_i N_i = mu1 n_i x acc_o(i).
  /// Backward: N_c(i) = N_i + N_c(i+1) + l_i n_i x F_c(i+1), F_c(i) = F_i + F_c(i+1); tau_i = N_c(i).
  [[gnu::always_inline]] Vec bias_torque(const Trig<J>& trig, const Vec& q_dot, double gravity_m_per_s2) const {
    std::array<double, J> fx{}, fy{}, moment{};
    double ax = 0.0, ay = gravity_m_per_s2, w = 0.0;
#pragma GCC unroll 4
    for (int i = 0; i < J; ++i) {
      w += q_dot(i);
      const double w2 = w * w, nx = trig.cos[i], ny = trig.sin[i];
      fx[i] = mass_[i] * ax - w2 * first_moment_[i] * nx;
      fy[i] = mass_[i] * ay - w2 * first_moment_[i] * ny;
      moment[i] = first_moment_[i] * (nx * ay - ny * ax);
      ax -= w2 * length_[i] * nx;
      ay -= w2 * length_[i] * ny;
    }
    Vec tau;
    double fcx = 0.0, fcy = 0.0, nc = 0.0;
#pragma GCC unroll 4
    for (int i = J - 1; i >= 0; --i) {
      nc += moment[i] + length_[i] * (trig.cos[i] * fcy - trig.sin[i] * fcx);
      fcx += fx[i];
      fcy += fy[i];
      tau(i) = nc;
    }
    return tau;
  }

  /// M(q), C(q, q_dot) q_dot and G(q) (the queries; the integrators use mass_matrix and bias_torque).
  void rigid_body(const Trig<J>& trig, const Vec& q_dot, Mat& M, Vec& coriolis, Vec& gravity) const {
    mass_matrix(trig, M);
    coriolis = bias_torque(trig, q_dot, 0.0);
    gravity = bias_torque(trig, Vec::Zero(), gravity_);
  }

  void rigid_body(const Vec& q, const Vec& q_dot, Mat& M, Vec& coriolis, Vec& gravity) const {
    rigid_body(Trig<J>::exact(q), q_dot, M, coriolis, gravity);
  }

  /// K (kappa o dp - q - z)
  Vec bellows_torque(const Vec& q, const Vec& z, const Vec& dp_bar) const {
    return stiffness_.cwiseProduct(kappa_.cwiseProduct(dp_bar) - q - z);
  }

  Vec stop_torque(const Vec& q, const Vec& q_dot) const {
    Vec torque = Vec::Zero();
#pragma GCC unroll 4
    for (int i = 0; i < J; ++i) {
      const double beyond = std::abs(q(i)) - stop_rad_(i);
      if (beyond > 0.0) {
        const double direction = q(i) > 0.0 ? 1.0 : -1.0;
        torque(i) = -stop_scale_(i) * (direction * stop_stiffness_ * beyond + stop_damping_ * q_dot(i));
      }
    }
    return torque;
  }

  /// q_ddot, with `trig` the sines and cosines at q.
  [[gnu::always_inline]] Vec acceleration(const Trig<J>& trig, const Vec& q, const Vec& q_dot, const Vec& z,
                                          const Vec& dp_bar) const {
    Mat M;
    mass_matrix(trig, M);
    const Vec bias = bias_torque(trig, q_dot, gravity_);
    Vec torque;
#pragma GCC unroll 4
    for (int i = 0; i < J; ++i) {
      torque(i) = stiffness_kappa_(i) * dp_bar(i) - stiffness_(i) * (q(i) + z(i)) - damping_(i) * q_dot(i) - bias(i);
      const double beyond = std::abs(q(i)) - stop_rad_(i);
      if (beyond > 0.0) {  // the hard stop, as stop_torque
        const double direction = q(i) > 0.0 ? 1.0 : -1.0;
        torque(i) -= stop_scale_(i) * (direction * stop_stiffness_ * beyond + stop_damping_ * q_dot(i));
      }
    }
    return solve_spd<J>(M, torque);
  }

  Vec acceleration(const Vec& q, const Vec& q_dot, const Vec& z, const Vec& dp_bar) const {
    return acceleration(Trig<J>::exact(q), q, q_dot, z, dp_bar);
  }

  Vec creep_rate(const Vec& q, const Vec& z) const {
    return (creep_gain_.cwiseProduct(q) - z).cwiseProduct(creep_rate_);
  }

  /// One classical RK4 step of (q, q_dot, z) with the pressure differences held; `trig` is at q
  /// before and after.
  void rk4(double h, const Vec& dp_bar, Vec& q, Vec& v, Vec& z, Trig<J>& trig) const {
    const Vec a1 = acceleration(trig, q, v, z, dp_bar), c1 = creep_rate(q, z);
    const Vec d2 = h / 2 * v, q2 = q + d2, v2 = v + h / 2 * a1, z2 = z + h / 2 * c1;
    const Vec a2 = acceleration(trig.advanced(d2, q2), q2, v2, z2, dp_bar), c2 = creep_rate(q2, z2);
    const Vec d3 = h / 2 * v2, q3 = q + d3, v3 = v + h / 2 * a2, z3 = z + h / 2 * c2;
    const Vec a3 = acceleration(trig.advanced(d3, q3), q3, v3, z3, dp_bar), c3 = creep_rate(q3, z3);
    const Vec d4 = h * v3, q4 = q + d4, v4 = v + h * a3, z4 = z + h * c3;
    const Vec a4 = acceleration(trig.advanced(d4, q4), q4, v4, z4, dp_bar), c4 = creep_rate(q4, z4);
    const Vec dq = h / 6.0 * (v + 2.0 * v2 + 2.0 * v3 + v4);
    q += dq;
    v += h / 6.0 * (a1 + 2.0 * a2 + 2.0 * a3 + a4);
    z += h / 6.0 * (c1 + 2.0 * c2 + 2.0 * c3 + c4);
    trig = trig.advanced(dq, q);
  }

 private:
  std::array<double, J> length_{}, mass_{}, first_moment_{}, second_moment_{};
  Vec stiffness_, kappa_, stiffness_kappa_, damping_, stop_scale_, stop_rad_, creep_gain_, creep_rate_;
  double gravity_, stop_stiffness_, stop_damping_;
};

}  // namespace bellows::arm_chain_kernel
