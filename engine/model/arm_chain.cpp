#include "engine/model/arm_chain.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <string>

#include "engine/model/arm_chain_kernel.hpp"
#include "engine/base/errors.hpp"

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

/// Calls f(std::integral_constant<int, J>) for the chain's joint count: the fixed-size kernel's J.
template <typename F>
decltype(auto) with_joint_count(int joints, F&& f) {
  switch (joints) {
    case 1:
      return f(std::integral_constant<int, 1>{});
    case 2:
      return f(std::integral_constant<int, 2>{});
    case 3:
      return f(std::integral_constant<int, 3>{});
    default:
      return f(std::integral_constant<int, kMaxJoints>{});  // validate_chain allows 1..kMaxJoints
  }
}

template <int J>
Eigen::Matrix<double, J, 1> fixed(const JointVector& v) {
  return v.head<J>();
}

}  // namespace

ArmChain::ArmChain(const ChainParameters& chain) : chain_(chain) {
  validate_chain(chain_);
  const int J = chain_.joints;
  stiffness_.resize(J);
  kappa_.resize(J);
  damping_ = JointVector::Zero(J);
  straight_inertia_ = JointVector::Zero(J);  // the kernel reads them; the mass matrix does not need them
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
  return with_joint_count(joints(), [&]<int J>(std::integral_constant<int, J>) {
    const arm_chain_kernel::Kernel<J> kernel(chain_, straight_inertia_, damping_);
    Eigen::Matrix<double, J, J> M;
    Eigen::Matrix<double, J, 1> coriolis, gravity;
    kernel.rigid_body(fixed<J>(q), fixed<J>(q_dot), M, coriolis, gravity);
    return RigidBodyTerms{M, coriolis, gravity};
  });
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
  return with_joint_count(joints(), [&]<int J>(std::integral_constant<int, J>) {
    const arm_chain_kernel::Kernel<J> kernel(chain_, straight_inertia_, damping_);
    return JointVector(kernel.bellows_torque(fixed<J>(q), fixed<J>(z), fixed<J>(dp_bar)));
  });
}

JointVector ArmChain::stop_torque(const JointVector& q, const JointVector& q_dot) const {
  return with_joint_count(joints(), [&]<int J>(std::integral_constant<int, J>) {
    const arm_chain_kernel::Kernel<J> kernel(chain_, straight_inertia_, damping_);
    return JointVector(kernel.stop_torque(fixed<J>(q), fixed<J>(q_dot)));
  });
}

JointVector ArmChain::acceleration(const JointVector& q, const JointVector& q_dot, const JointVector& z,
                                   const JointVector& dp_bar) const {
  return with_joint_count(joints(), [&]<int J>(std::integral_constant<int, J>) {
    const arm_chain_kernel::Kernel<J> kernel(chain_, straight_inertia_, damping_);
    return JointVector(kernel.acceleration(fixed<J>(q), fixed<J>(q_dot), fixed<J>(z), fixed<J>(dp_bar)));
  });
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

void ArmChain::advance(double dt_s, const JointVector& dp_bar) {
  with_joint_count(joints(), [&]<int J>(std::integral_constant<int, J>) {
    const arm_chain_kernel::Kernel<J> kernel(chain_, straight_inertia_, damping_);
    Eigen::Matrix<double, J, 1> q = fixed<J>(state_.angle_rad), v = fixed<J>(state_.velocity_rad_per_s),
                                z = fixed<J>(state_.creep_rad);
    const Eigen::Matrix<double, J, 1> dp = fixed<J>(dp_bar);
    constexpr double kEpsilon_s = 1e-12;  // no sliver steps from float drift
    arm_chain_kernel::Trig<J> trig;
    double remaining = dt_s;
    for (int step = 0; remaining > kEpsilon_s; ++step) {
      if (step % arm_chain_kernel::kTrigRefreshSteps == 0) trig = arm_chain_kernel::Trig<J>::exact(q);
      const double h = std::min(chain_.integration_step_s, remaining);
      kernel.rk4(h, dp, q, v, z, trig);
      state_.time_s += h;
      remaining -= h;
    }
    state_.angle_rad = q;
    state_.velocity_rad_per_s = v;
    state_.creep_rad = z;
  });
}

void ArmChain::set_state(const State& state) {
  const Eigen::Index J = joints();
  if (state.angle_rad.size() != J || state.velocity_rad_per_s.size() != J || state.creep_rad.size() != J) {
    throw InputError("arm state: angle, velocity and creep need " + std::to_string(J) + " entries each");
  }
  state_ = state;
}

}  // namespace bellows
