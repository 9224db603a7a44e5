#include "engine/model/arm_chain_parameters.hpp"

#include <tuple>

#include <cmath>
#include <string>

#include "engine/base/errors.hpp"
#include "engine/base/parameters.hpp"

namespace bellows {
namespace {

ChainLink preset_link(double m, double l, double c, double I, double m_a, double K, double kappa, double w0,
                      double delta) {
  ChainLink out;
  out.mass_kg = m;
  out.length_m = l;
  out.center_of_mass_m = c;
  out.inertia_kg_m2 = I;
  out.tip_mass_kg = m_a;
  out.stiffness_Nm_per_rad = K;
  out.kappa_rad_per_bar = kappa;
  out.omega0_straight_rad_per_s = w0;
  out.damping_ratio = delta;
  return out;
}

}  // namespace

ChainParameters chain_preset(std::string_view name) {
  // ../shared/spec/multi-joint.md section 2 (reconstructed values), column for column:
  //                 m     l     c      I        m_a   K     kappa w0     delta
  ChainParameters chain;
  if (name == "arm2") {
    chain.joints = 2;
    chain.links[0] = preset_link(0.40, 0.25, 0.125, 2.08e-3, 0.30, 2.81, 5.0, 8.0, 0.31);  // shoulder
    chain.links[1] = preset_link(0.10, 0.30, 0.15, 7.5e-4, 0.0, 0.60, 7.91, 14.14, 0.31);  // elbow: the paper's arm
  } else if (name == "arm3") {
    chain.joints = 3;
    chain.links[0] = preset_link(0.40, 0.25, 0.125, 2.08e-3, 0.30, 4.13, 5.0, 6.0, 0.31);  // shoulder
    chain.links[1] = preset_link(0.10, 0.30, 0.15, 7.5e-4, 0.15, 2.63, 6.0, 10.0, 0.31);   // elbow
    chain.links[2] = preset_link(0.06, 0.20, 0.10, 2.0e-4, 0.0, 0.16, 7.91, 14.14, 0.31);  // wrist
  } else {
    std::string known;
    for (std::string_view preset : kArmPresets) known += (known.empty() ? "" : ", ") + std::string(preset);
    throw InputError("unknown arm preset '" + std::string(name) + "' (known: " + known + ")");
  }
  return chain;
}

void validate_chain(const ChainParameters& chain) {
  if (chain.joints < 1 || chain.joints > kMaxJoints) {
    throw InputError("an arm needs 1 to " + std::to_string(kMaxJoints) + " joints, got " +
                     std::to_string(chain.joints));
  }
  auto check = [](bool ok, int joint, const char* what, double value) {
    if (!ok) throw InputError("arm joint " + std::to_string(joint + 1) + ": " + what + " = " + std::to_string(value));
  };
  for (int i = 0; i < chain.joints; ++i) {
    const ChainLink& l = chain.links[static_cast<std::size_t>(i)];
    check(l.mass_kg >= 0.0 && std::isfinite(l.mass_kg), i, "mass_kg must be >= 0", l.mass_kg);
    check(l.length_m >= 0.0 && std::isfinite(l.length_m), i, "length_m must be >= 0", l.length_m);
    check(std::isfinite(l.center_of_mass_m), i, "center_of_mass_m must be finite", l.center_of_mass_m);
    check(l.inertia_kg_m2 >= 0.0 && std::isfinite(l.inertia_kg_m2), i, "inertia_kg_m2 must be >= 0", l.inertia_kg_m2);
    check(l.tip_mass_kg >= 0.0 && std::isfinite(l.tip_mass_kg), i, "tip_mass_kg must be >= 0", l.tip_mass_kg);
    check(l.stiffness_Nm_per_rad > 0.0 && std::isfinite(l.stiffness_Nm_per_rad), i, "stiffness_Nm_per_rad must be > 0",
          l.stiffness_Nm_per_rad);
    check(std::isfinite(l.kappa_rad_per_bar), i, "kappa_rad_per_bar must be finite", l.kappa_rad_per_bar);
    check(l.omega0_straight_rad_per_s > 0.0 && std::isfinite(l.omega0_straight_rad_per_s), i,
          "omega0_straight_rad_per_s must be > 0", l.omega0_straight_rad_per_s);
    check(l.damping_ratio >= 0.0 && std::isfinite(l.damping_ratio), i, "damping_ratio must be >= 0", l.damping_ratio);
    check(l.creep_gain >= 0.0 && std::isfinite(l.creep_gain), i, "creep_gain must be >= 0", l.creep_gain);
    check(l.creep_tau_s > 0.0 && std::isfinite(l.creep_tau_s), i, "creep_tau_s must be > 0", l.creep_tau_s);
    check(l.hard_stop_deg > 0.0, i, "hard_stop_deg must be > 0", l.hard_stop_deg);
  }
  if (!(chain.gravity_m_per_s2 >= 0.0) || !(chain.hard_stop_stiffness_per_s2 >= 0.0) ||
      !(chain.hard_stop_damping_per_s >= 0.0) || !(chain.integration_step_s > 0.0)) {
    throw InputError(
        "arm: gravity_m_per_s2 and the hard stops' stiffness and damping must be >= 0, integration_step_s > 0");
  }
}

ChainParameters chain_of(const ArmParameters& arm) {
  static_assert(std::tuple_size_v<decltype(ArmParameters::joint)> == kMaxJoints);
  if (!arm.preset.empty()) return chain_preset(arm.preset);
  if (arm.joints < 2 || arm.joints > kMaxJoints) {
    throw InputError("an arm of several joints needs [arm] preset (arm2 or arm3) or [arm] joints (2 to 4)");
  }
  ChainParameters chain;
  chain.joints = arm.joints;
  chain.gravity = arm.gravity != 0;
  for (int j = 0; j < arm.joints; ++j) {
    const ArmJointParameters& p = arm.joint[static_cast<std::size_t>(j)];
    chain.links[static_cast<std::size_t>(j)] =
        preset_link(p.mass_kg, p.length_m, p.center_of_mass_m, p.inertia_kg_m2, p.tip_mass_kg, p.stiffness_Nm_per_rad,
                    p.kappa_rad_per_bar, p.omega0_straight_rad_per_s, p.damping_ratio);
  }
  return chain;
}

int arm_joint_count(const ArmParameters& arm) { return arm.has_chain() ? chain_of(arm).joints : 1; }

}  // namespace bellows
