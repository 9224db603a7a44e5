// The parameters of a simulated arm of J joints (../shared/spec/multi-joint.md sections 1 and 2):
// per link its rigid body, per joint its bellows' stiffness, gain, damping, creep and hard stops.
// Presets `arm2` and `arm3` carry the spec's tables. The engine knows no TOML: loading a chain from
// a file is app/'s business, into this struct.
#pragma once

#include <array>
#include <string>
#include <string_view>

#include "engine/model/multi_joint_model.hpp"

namespace bellows {

/// One link and the joint that drives it (joint i turns link i relative to link i-1).
struct ChainLink {
  double mass_kg = 0.0;                    // m_i
  double length_m = 0.0;                   // l_i, joint to the next joint
  double center_of_mass_m = 0.0;           // c_i, from the joint
  double inertia_kg_m2 = 0.0;              // I_i, about the link's centre of mass
  double tip_mass_kg = 0.0;                // m_a,i, point mass at the distal end (next joint's bellows)
  double stiffness_Nm_per_rad = 0.0;       // K_i, the bellows' spring-like retraction
  double kappa_rad_per_bar = 0.0;          // torque per bar is K_i kappa_i
  double omega0_straight_rad_per_s = 0.0;  // w0 with the arm straight: K_i = w0^2 M_ii(q = 0)
  double damping_ratio = 0.0;              // delta: D_i = 2 delta w0 M_ii(q = 0)
  double creep_gain = 0.25;                // c_z, as for one joint (reference-system.md section 4)
  double creep_tau_s = 0.8;                // tau_z
  double hard_stop_deg = 95.0;             // stops beyond +-this, relative to the previous link
};

struct ChainParameters {
  int joints = 0;
  std::array<ChainLink, kMaxJoints> links{};
  bool gravity = true;  // false: the arm moves in the horizontal plane
  double gravity_m_per_s2 = 9.81;
  // Hard stops as for one joint (PlantParameters), in angular acceleration per rad and per rad/s,
  // scaled by each joint's straight-arm inertia M_ii(0) into torques.
  double hard_stop_stiffness_per_s2 = 1.0e4;
  double hard_stop_damping_per_s = 140.0;
  double integration_step_s = 1.0e-4;  // fixed internal step (RK4), as for one joint
};

/// "arm2" (shoulder, elbow) or "arm3" (shoulder, elbow, wrist) with the spec's numbers; throws
/// InputError naming the known presets otherwise.
ChainParameters chain_preset(std::string_view name);

/// The chain `[arm]` describes: its preset's, or the chain of its own keys ([arm] joints,
/// [arm] gravity, [arm_joint1] ..). InputError when the arm is one joint (no chain) or unknown.
ChainParameters chain_of(const ArmParameters& arm);
/// The joints of `arm`: its chain's, or 1 without one.
int arm_joint_count(const ArmParameters& arm);

/// Throws InputError naming the joint and the value when a chain cannot be simulated: joint count
/// outside 1..kMaxJoints, a negative or non-finite mass, length or inertia, K, w0, tau_z or the
/// integration step not positive, a negative damping ratio or creep gain. (ArmChain also refuses a
/// chain whose mass matrix is singular.)
void validate_chain(const ChainParameters& chain);

}  // namespace bellows
