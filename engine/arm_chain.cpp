#include "engine/arm_chain.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <string>

#include "engine/errors.hpp"

namespace bellows {
namespace {

/// Absolute angles theta_k = q_1 + ... + q_k of the links and their sines and cosines.
struct LinkAngles {
  JointVector sin, cos;
  explicit LinkAngles(const JointVector& q) : sin(q.size()), cos(q.size()) {
    double theta = 0.0;
    for (Eigen::Index k = 0; k < q.size(); ++k) {
      theta += q(k);
      sin(k) = std::sin(theta);
      cos(k) = std::cos(theta);
    }
  }
};

/// The Jacobian of a point on link i at distance d from its joint: column j (j <= i) is
/// d(x, y)/dq_j = sum_{k=j}^{i-1} l_k (-sin theta_k, cos theta_k) + d (-sin theta_i, cos theta_i).
struct PointJacobian {
  JointVector x, y;  // rows of the 2 x J Jacobian; zero beyond link i
  PointJacobian(const ChainParameters& chain, const LinkAngles& angles, int link, double distance_m)
      : x(JointVector::Zero(chain.joints)), y(JointVector::Zero(chain.joints)) {
    double jx = -distance_m * angles.sin(link), jy = distance_m * angles.cos(link);
    for (int j = link; j >= 0; --j) {
      if (j < link) {
        const double l = chain.links[static_cast<std::size_t>(j)].length_m;
        jx -= l * angles.sin(j);
        jy += l * angles.cos(j);
      }
      x(j) = jx;
      y(j) = jy;
    }
  }
};

/// Calls f(link, distance_m, mass_kg) for every point mass of the chain: each link's centre of mass
/// and the point mass at its distal end. (Each link's rotational inertia is added separately.)
template <typename F>
void for_each_point_mass(const ChainParameters& chain, F&& f) {
  for (int i = 0; i < chain.joints; ++i) {
    const ChainLink& l = chain.links[static_cast<std::size_t>(i)];
    if (l.mass_kg > 0.0) f(i, l.center_of_mass_m, l.mass_kg);
    if (l.tip_mass_kg > 0.0) f(i, l.length_m, l.tip_mass_kg);
  }
}

}  // namespace

ArmChain::ArmChain(const ChainParameters& chain) : chain_(chain) {
  validate_chain(chain_);
  const int J = chain_.joints;
  stiffness_.resize(J);
  kappa_.resize(J);
  damping_.resize(J);
  for (int i = 0; i < J; ++i) {
    stiffness_(i) = chain_.links[static_cast<std::size_t>(i)].stiffness_Nm_per_rad;
    kappa_(i) = chain_.links[static_cast<std::size_t>(i)].kappa_rad_per_bar;
  }
  const JointMatrix straight = mass_matrix(JointVector::Zero(J));
  if (Eigen::LLT<JointMatrix>(straight).info() != Eigen::Success || !(straight.diagonal().minCoeff() > 0.0)) {
    throw InputError("arm: the links have no inertia about some joint (the mass matrix is singular)");
  }
  straight_inertia_ = straight.diagonal();
  for (int i = 0; i < J; ++i) {
    const ChainLink& l = chain_.links[static_cast<std::size_t>(i)];
    damping_(i) = 2.0 * l.damping_ratio * l.omega0_straight_rad_per_s * straight_inertia_(i);
  }
  state_.angle_rad = JointVector::Zero(J);
  state_.velocity_rad_per_s = JointVector::Zero(J);
  state_.creep_rad = JointVector::Zero(J);
}

ArmChain::RigidBodyTerms ArmChain::rigid_body_terms(const JointVector& q, const JointVector& q_dot) const {
  // Over the point masses m with Jacobian J_p: M += m J_p'J_p, C q_dot += m J_p' (J_p_dot q_dot),
  // G += m g (dy/dq); each link's rotational inertia I_i adds I_i to M over joints 1..i (its angular
  // Jacobian is constant, so it adds nothing to C q_dot). J_p_dot q_dot of a point on link i at
  // distance d is -sum_{k<i} l_k w_k^2 (cos theta_k, sin theta_k) - d w_i^2 (cos theta_i, sin theta_i),
  // w_k = theta_k_dot the absolute angular velocity of link k.
  const int J = joints();
  const LinkAngles angles(q);
  JointVector link_rate(J);
  double rate = 0.0;
  for (int k = 0; k < J; ++k) link_rate(k) = rate += q_dot(k);
  RigidBodyTerms terms{JointMatrix::Zero(J, J), JointVector::Zero(J), JointVector::Zero(J)};
  const double g = chain_.gravity ? chain_.gravity_m_per_s2 : 0.0;
  for_each_point_mass(chain_, [&](int link, double distance_m, double mass_kg) {
    const PointJacobian jacobian(chain_, angles, link, distance_m);
    terms.mass.noalias() += mass_kg * (jacobian.x * jacobian.x.transpose() + jacobian.y * jacobian.y.transpose());
    const double w2 = link_rate(link) * link_rate(link);
    double ax = -distance_m * w2 * angles.cos(link), ay = -distance_m * w2 * angles.sin(link);
    for (int k = 0; k < link; ++k) {
      const double centripetal = chain_.links[static_cast<std::size_t>(k)].length_m * link_rate(k) * link_rate(k);
      ax -= centripetal * angles.cos(k);
      ay -= centripetal * angles.sin(k);
    }
    terms.coriolis += mass_kg * (jacobian.x * ax + jacobian.y * ay);
    terms.gravity += mass_kg * g * jacobian.y;
  });
  for (int i = 0; i < J; ++i) {
    terms.mass.topLeftCorner(i + 1, i + 1).array() += chain_.links[static_cast<std::size_t>(i)].inertia_kg_m2;
  }
  return terms;
}

JointMatrix ArmChain::mass_matrix(const JointVector& q) const {
  return rigid_body_terms(q, JointVector::Zero(joints())).mass;
}

JointVector ArmChain::coriolis_torque(const JointVector& q, const JointVector& q_dot) const {
  return rigid_body_terms(q, q_dot).coriolis;
}

JointVector ArmChain::gravity_torque(const JointVector& q) const {
  return rigid_body_terms(q, JointVector::Zero(joints())).gravity;
}

JointMatrix ArmChain::gravity_stiffness(const JointVector& q) const {
  // d/dq_m of dy/dq_j is dx/dq_max(j, m) for j, m <= i (the Jacobian's x row), zero beyond link i.
  const int J = joints();
  JointMatrix stiffness = JointMatrix::Zero(J, J);
  if (!chain_.gravity) return stiffness;
  const LinkAngles angles(q);
  for_each_point_mass(chain_, [&](int link, double distance_m, double mass_kg) {
    const PointJacobian jacobian(chain_, angles, link, distance_m);
    for (int j = 0; j <= link; ++j) {
      for (int m = 0; m <= link; ++m) stiffness(j, m) += mass_kg * chain_.gravity_m_per_s2 * jacobian.x(std::max(j, m));
    }
  });
  return stiffness;
}

JointVector ArmChain::bellows_torque(const JointVector& q, const JointVector& z, const JointVector& dp_bar) const {
  return stiffness_.cwiseProduct(kappa_.cwiseProduct(dp_bar) - q - z);
}

JointVector ArmChain::stop_torque(const JointVector& q, const JointVector& q_dot) const {
  const int J = joints();
  JointVector torque = JointVector::Zero(J);
  for (int i = 0; i < J; ++i) {
    const double stop_rad = chain_.links[static_cast<std::size_t>(i)].hard_stop_deg * std::numbers::pi / 180.0;
    const double beyond = std::abs(q(i)) - stop_rad;
    if (beyond > 0.0) {
      const double direction = q(i) > 0.0 ? 1.0 : -1.0;
      torque(i) = -straight_inertia_(i) *
                  (direction * chain_.hard_stop_stiffness_per_s2 * beyond + chain_.hard_stop_damping_per_s * q_dot(i));
    }
  }
  return torque;
}

JointVector ArmChain::acceleration(const JointVector& q, const JointVector& q_dot, const JointVector& z,
                                   const JointVector& dp_bar) const {
  const RigidBodyTerms terms = rigid_body_terms(q, q_dot);
  const JointVector torque = bellows_torque(q, z, dp_bar) - damping_.cwiseProduct(q_dot) + stop_torque(q, q_dot) -
                             terms.coriolis - terms.gravity;
  return terms.mass.llt().solve(torque);
}

JointVector ArmChain::holding_pressure_bar(const JointVector& q) const {
  JointVector dp(joints());
  const JointVector gravity = gravity_torque(q);
  for (int i = 0; i < joints(); ++i) {
    const double settled_creep = chain_.links[static_cast<std::size_t>(i)].creep_gain * q(i);
    dp(i) = (gravity(i) / stiffness_(i) + q(i) + settled_creep) / kappa_(i);
  }
  return dp;
}

double ArmChain::mechanical_energy_J(const State& state) const {
  const JointVector& q = state.angle_rad;
  const JointVector& q_dot = state.velocity_rad_per_s;
  double energy = 0.5 * q_dot.dot(mass_matrix(q) * q_dot) + 0.5 * q.dot(stiffness_.cwiseProduct(q));
  if (chain_.gravity) {
    const LinkAngles angles(q);
    for_each_point_mass(chain_, [&](int link, double distance_m, double mass_kg) {
      // height y = -(dx/dq_1): the Jacobian's first column is (-y, x) of the point
      energy += mass_kg * chain_.gravity_m_per_s2 * -PointJacobian(chain_, angles, link, distance_m).x(0);
    });
  }
  return energy;
}

ArmChain::Derivative ArmChain::derivative(const JointVector& q, const JointVector& q_dot, const JointVector& z,
                                          const JointVector& dp_bar) const {
  Derivative d;
  d.angle = q_dot;
  d.velocity = acceleration(q, q_dot, z, dp_bar);
  d.creep.resize(joints());
  for (int i = 0; i < joints(); ++i) {
    const ChainLink& l = chain_.links[static_cast<std::size_t>(i)];
    d.creep(i) = (l.creep_gain * q(i) - z(i)) / l.creep_tau_s;
  }
  return d;
}

void ArmChain::step(double h, const JointVector& dp_bar) {
  // Classical RK4, the pressure differences constant over the step.
  const JointVector& q = state_.angle_rad;
  const JointVector& v = state_.velocity_rad_per_s;
  const JointVector& z = state_.creep_rad;
  const Derivative k1 = derivative(q, v, z, dp_bar);
  const Derivative k2 = derivative(q + h / 2 * k1.angle, v + h / 2 * k1.velocity, z + h / 2 * k1.creep, dp_bar);
  const Derivative k3 = derivative(q + h / 2 * k2.angle, v + h / 2 * k2.velocity, z + h / 2 * k2.creep, dp_bar);
  const Derivative k4 = derivative(q + h * k3.angle, v + h * k3.velocity, z + h * k3.creep, dp_bar);
  state_.angle_rad += h / 6.0 * (k1.angle + 2.0 * k2.angle + 2.0 * k3.angle + k4.angle);
  state_.velocity_rad_per_s += h / 6.0 * (k1.velocity + 2.0 * k2.velocity + 2.0 * k3.velocity + k4.velocity);
  state_.creep_rad += h / 6.0 * (k1.creep + 2.0 * k2.creep + 2.0 * k3.creep + k4.creep);
  state_.time_s += h;
}

void ArmChain::advance(double dt_s, const JointVector& dp_bar) {
  constexpr double kEpsilon_s = 1e-12;  // no sliver steps from float drift
  double remaining = dt_s;
  while (remaining > kEpsilon_s) {
    const double h = std::min(chain_.integration_step_s, remaining);
    step(h, dp_bar);
    remaining -= h;
  }
}

void ArmChain::set_state(const State& state) {
  const Eigen::Index J = joints();
  if (state.angle_rad.size() != J || state.velocity_rad_per_s.size() != J || state.creep_rad.size() != J) {
    throw InputError("arm state: angle, velocity and creep need " + std::to_string(J) + " entries each");
  }
  state_ = state;
}

}  // namespace bellows
