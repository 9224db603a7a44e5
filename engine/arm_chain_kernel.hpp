// The chain's equations (engine/arm_chain.hpp) for exactly J joints, with fixed-size matrices so that
// the compiler unrolls them: the integrator's right-hand side runs ~40 000 times per simulated second.
// Internal to arm_chain.cpp; ArmChain's interface is the place to read what the terms mean.
#pragma once

#include <array>
#include <cmath>
#include <numbers>

#include <Eigen/Dense>

#include "engine/arm_chain_parameters.hpp"

namespace bellows::arm_chain_kernel {

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
      inertia_[i] = l.inertia_kg_m2;
      stiffness_(i) = l.stiffness_Nm_per_rad;
      kappa_(i) = l.kappa_rad_per_bar;
      damping_(i) = damping(i);
      stop_scale_(i) = straight_inertia(i);
      stop_rad_(i) = l.hard_stop_deg * std::numbers::pi / 180.0;
      creep_gain_(i) = l.creep_gain;
      creep_rate_(i) = 1.0 / l.creep_tau_s;
      if (l.mass_kg > 0.0) points_[points_count_++] = {i, l.center_of_mass_m, l.mass_kg};
      if (l.tip_mass_kg > 0.0) points_[points_count_++] = {i, l.length_m, l.tip_mass_kg};
    }
  }

  /// M(q), C(q, q_dot) q_dot and G(q): over the point masses m with Jacobian J_p, M += m J_p'J_p,
  /// C q_dot += m J_p' (J_p_dot q_dot), G += m g dy/dq; link i's own inertia adds I_i over joints 1..i.
  /// Column j <= i of J_p for a point on link i at distance d is
  ///   sum_{k=j}^{i-1} l_k (-sin theta_k, cos theta_k) + d (-sin theta_i, cos theta_i),
  /// and J_p_dot q_dot = -sum_{k<i} l_k w_k^2 (cos theta_k, sin theta_k) - d w_i^2 (cos theta_i, sin theta_i),
  /// theta_k = q_1 + ... + q_k, w_k its rate.
  void rigid_body(const Vec& q, const Vec& q_dot, Mat& M, Vec& coriolis, Vec& gravity) const {
    std::array<double, J> sin{}, cos{}, rate{};
    double theta = 0.0, w = 0.0;
    for (int k = 0; k < J; ++k) {
      theta += q(k);
      w += q_dot(k);
      sin[k] = std::sin(theta);
      cos[k] = std::cos(theta);
      rate[k] = w;
    }
    M.setZero();
    coriolis.setZero();
    gravity.setZero();
    for (int p = 0; p < points_count_; ++p) {
      const Point& point = points_[p];
      const int i = point.link;
      std::array<double, J> jx{}, jy{};
      double x = -point.distance_m * sin[i], y = point.distance_m * cos[i];
      double ax = -point.distance_m * rate[i] * rate[i] * cos[i], ay = -point.distance_m * rate[i] * rate[i] * sin[i];
      for (int j = i; j >= 0; --j) {
        if (j < i) {
          x -= length_[j] * sin[j];
          y += length_[j] * cos[j];
          const double centripetal = length_[j] * rate[j] * rate[j];
          ax -= centripetal * cos[j];
          ay -= centripetal * sin[j];
        }
        jx[j] = x;
        jy[j] = y;
      }
      const double m = point.mass_kg;
      for (int a = 0; a <= i; ++a) {
        for (int b = 0; b <= a; ++b) M(a, b) += m * (jx[a] * jx[b] + jy[a] * jy[b]);
        coriolis(a) += m * (jx[a] * ax + jy[a] * ay);
        gravity(a) += m * gravity_ * jy[a];
      }
    }
    for (int i = 0; i < J; ++i) {
      for (int a = 0; a <= i; ++a) {
        for (int b = 0; b <= a; ++b) M(a, b) += inertia_[i];
      }
    }
    for (int a = 0; a < J; ++a) {
      for (int b = a + 1; b < J; ++b) M(a, b) = M(b, a);
    }
  }

  /// K (kappa o dp - q - z)
  Vec bellows_torque(const Vec& q, const Vec& z, const Vec& dp_bar) const {
    return stiffness_.cwiseProduct(kappa_.cwiseProduct(dp_bar) - q - z);
  }

  Vec stop_torque(const Vec& q, const Vec& q_dot) const {
    Vec torque = Vec::Zero();
    for (int i = 0; i < J; ++i) {
      const double beyond = std::abs(q(i)) - stop_rad_(i);
      if (beyond > 0.0) {
        const double direction = q(i) > 0.0 ? 1.0 : -1.0;
        torque(i) = -stop_scale_(i) * (direction * stop_stiffness_ * beyond + stop_damping_ * q_dot(i));
      }
    }
    return torque;
  }

  Vec acceleration(const Vec& q, const Vec& q_dot, const Vec& z, const Vec& dp_bar) const {
    Mat M;
    Vec coriolis, gravity;
    rigid_body(q, q_dot, M, coriolis, gravity);
    const Vec torque =
        bellows_torque(q, z, dp_bar) - damping_.cwiseProduct(q_dot) + stop_torque(q, q_dot) - coriolis - gravity;
    return M.llt().solve(torque);
  }

  Vec creep_rate(const Vec& q, const Vec& z) const { return (creep_gain_.cwiseProduct(q) - z).cwiseProduct(creep_rate_); }

  /// One classical RK4 step of (q, q_dot, z) with the pressure differences held.
  void rk4(double h, const Vec& dp_bar, Vec& q, Vec& v, Vec& z) const {
    const Vec a1 = acceleration(q, v, z, dp_bar), c1 = creep_rate(q, z);
    const Vec q2 = q + h / 2 * v, v2 = v + h / 2 * a1, z2 = z + h / 2 * c1;
    const Vec a2 = acceleration(q2, v2, z2, dp_bar), c2 = creep_rate(q2, z2);
    const Vec q3 = q + h / 2 * v2, v3 = v + h / 2 * a2, z3 = z + h / 2 * c2;
    const Vec a3 = acceleration(q3, v3, z3, dp_bar), c3 = creep_rate(q3, z3);
    const Vec q4 = q + h * v3, v4 = v + h * a3, z4 = z + h * c3;
    const Vec a4 = acceleration(q4, v4, z4, dp_bar), c4 = creep_rate(q4, z4);
    q += h / 6.0 * (v + 2.0 * v2 + 2.0 * v3 + v4);
    v += h / 6.0 * (a1 + 2.0 * a2 + 2.0 * a3 + a4);
    z += h / 6.0 * (c1 + 2.0 * c2 + 2.0 * c3 + c4);
  }

 private:
  struct Point {
    int link = 0;
    double distance_m = 0.0, mass_kg = 0.0;
  };
  std::array<Point, 2 * J> points_{};
  int points_count_ = 0;
  std::array<double, J> length_{}, inertia_{};
  Vec stiffness_, kappa_, damping_, stop_scale_, stop_rad_, creep_gain_, creep_rate_;
  double gravity_, stop_stiffness_, stop_damping_;
};

}  // namespace bellows::arm_chain_kernel
