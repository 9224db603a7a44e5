// The mechanics of a simulated arm of J joints (../shared/spec/multi-joint.md section 1): a planar
// serial chain of rigid links in a vertical plane (gravity along -y, or none), q_i the angle of link i
// relative to link i-1, q = 0 stretched out horizontally, driven by each joint's bellows:
//
//   M(q) q_ddot + C(q, q_dot) q_dot + G(q) = K (kappa o dp - q - z) - D q_dot + tau_stops
//   z_dot = (c_z q - z) / tau_z
//
// with D_i = 2 delta_i w0_i M_ii(0). With one joint, no gravity and M_11 = K / w0^2 this is the
// single-joint arm of reference-system.md section 4. The bellows' pneumatics (valves, pressures) are
// not here: the input is each joint's pressure difference dp_i (bar), held over advance(). Fixed
// internal RK4 step, no randomness: the same inputs give the same states bit for bit, and a state
// read with state() and written back with set_state() resumes exactly. Nothing allocates after
// construction (fixed-capacity vectors).
#pragma once

#include "engine/model/arm_chain_parameters.hpp"

namespace bellows {

class ArmChain {
 public:
  struct State {
    double time_s = 0.0;
    JointVector angle_rad;           // q
    JointVector velocity_rad_per_s;  // q_dot
    JointVector creep_rad;           // z
  };

  /// Validates the chain (InputError, also for a mass matrix that is singular at q = 0); starts at
  /// rest, stretched out, without creep.
  explicit ArmChain(const ChainParameters& chain);

  int joints() const { return chain_.joints; }
  const ChainParameters& parameters() const { return chain_; }

  /// M(q), C(q, q_dot) q_dot and G(q) in one pass over the links (what the integrator uses).
  struct RigidBodyTerms {
    JointMatrix mass;
    JointVector coriolis, gravity;
  };
  RigidBodyTerms rigid_body_terms(const JointVector& q, const JointVector& q_dot) const;

  // The rigid body (spec section 1), for any q, q_dot of joints() entries.
  JointMatrix mass_matrix(const JointVector& q) const;                                // M(q)
  JointVector coriolis_torque(const JointVector& q, const JointVector& q_dot) const;  // C(q, q_dot) q_dot
  JointVector gravity_torque(const JointVector& q) const;                             // G(q) = dV_g/dq
  JointMatrix gravity_stiffness(const JointVector& q) const;                          // dG/dq
  /// K (kappa o dp - q - z): what the bellows exert.
  JointVector bellows_torque(const JointVector& q, const JointVector& z, const JointVector& dp_bar) const;
  /// The hard stops beyond each joint's range: M_ii(0) (k_stop * overshoot + c_stop * q_dot_i), opposing.
  JointVector stop_torque(const JointVector& q, const JointVector& q_dot) const;
  /// q_ddot from the equation above.
  JointVector acceleration(const JointVector& q, const JointVector& q_dot, const JointVector& z,
                           const JointVector& dp_bar) const;

  /// M_ii(0): each joint's inertia with the arm stretched out (the spec's "inertia about each joint").
  const JointVector& straight_inertia_kg_m2() const { return straight_inertia_; }
  /// D_i = 2 delta_i w0_i M_ii(0) (N m s/rad).
  const JointVector& damping_Nms_per_rad() const { return damping_; }
  /// The pressure differences that hold the arm still at `q` once creep has settled (z = c_z q):
  /// K (kappa o dp - (1 + c_z) q) = G(q).
  JointVector holding_pressure_bar(const JointVector& q) const;

  /// Kinetic + gravitational + the bellows' spring energy 1/2 sum K_i q_i^2 (J), zero potential at
  /// y = 0. Conserved without input, damping, creep and stops.
  double mechanical_energy_J(const State& state) const;

  /// Advances by dt_s with the pressure differences held (steps of integration_step_s; the last one shorter).
  void advance(double dt_s, const JointVector& dp_bar);
  const State& state() const { return state_; }
  /// Throws InputError when the vectors do not have joints() entries.
  void set_state(const State& state);

 private:
  ChainParameters chain_;
  JointVector stiffness_, kappa_;
  JointVector straight_inertia_, damping_;
  State state_;
};

}  // namespace bellows
