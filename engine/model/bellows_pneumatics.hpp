// The bellows of one joint (reference-system.md section 4): chambers A and B, each filled from the
// supply by its inlet valves and emptied to ambient by its outlet valves (switching valves with real
// PWM timing, ISO 6358 flow), their volumes depending on the joint's angle, with the full gas law.
// One implementation for the single-joint simulated arm (devices/simulated_arm) and every joint of the
// J-joint one (engine/model/pneumatic_arm_chain): the same physics per joint. Inline: it is the inner loop
// of both integrators (four right-hand sides per 0.1 ms step).
#pragma once

#include <algorithm>
#include <array>
#include <cmath>

#include "engine/base/parameters.hpp"

namespace bellows {

/// One joint's bellows pair and its valves (the plant's truth, not the controller's nominal model).
struct BellowsParameters {
  double volume_l = 0.45;                        // V0, average volume of one bellows
  double volume_gain_per_rad = 0.35;             // beta: V_A,B = V0 (1 +- beta q)
  double valve_conductance_m3_per_sPa = 3.0e-9;  // C of one valve
  double valve_critical_ratio = 0.35;            // b
  int valves_per_port = 2;                       // inlets (and outlets) per chamber
};

/// The single-joint arm's bellows.
inline BellowsParameters bellows_of(const PlantParameters& plant) {
  return {plant.volume_l, plant.volume_gain_per_rad, plant.valve_conductance_m3_per_sPa, plant.valve_critical_ratio,
          plant.valves_per_port};
}

/// Duty cycles of one joint's valves for the PWM period in progress, in [0, 1]; index 0 is chamber A.
/// Both inlets of a chamber share one duty, both outlets another (reference-system.md section 1).
struct BellowsDuties {
  std::array<double, 2> inlet{}, outlet{};
};

/// Which of one joint's valves are open.
struct BellowsOpenings {
  std::array<bool, 2> inlet{}, outlet{};
};

/// Each valve is fully open for the first duty * period of every period, closed for the rest.
inline BellowsOpenings pwm_openings(const BellowsDuties& duties, double phase_s, double period_s) {
  BellowsOpenings open;
  for (int i = 0; i < 2; ++i) {
    open.inlet[i] = phase_s < duties.inlet[i] * period_s;
    open.outlet[i] = phase_s < duties.outlet[i] * period_s;
  }
  return open;
}

/// Time from `phase_s` to the next edge of one joint's valves, at most to the period's end (where the
/// period restarts and every valve with a duty above 0 opens). An integrator's steps end on edges, so
/// that the openings are constant over each step.
inline double pwm_time_to_next_edge(const BellowsDuties& duties, double phase_s, double period_s) {
  double next = period_s - phase_s;
  for (int i = 0; i < 2; ++i) {
    for (double duty : {duties.inlet[i], duties.outlet[i]}) {
      const double edge = duty * period_s - phase_s;
      if (edge > 0.0) next = std::min(next, edge);
    }
  }
  return next;
}

/// The chamber pressures' right-hand side for one joint, with the parameters converted once.
class BellowsPneumatics {
 public:
  BellowsPneumatics() = default;
  BellowsPneumatics(const BellowsParameters& bellows, const GasParameters& gas)
      : rt_(gas.gas_constant_J_per_kgK * gas.temperature_K),
        ambient_Pa_(gas.ambient_bar * 1e5),
        v0_m3_(bellows.volume_l * 1e-3),
        beta_(bellows.volume_gain_per_rad),
        v0_beta_(v0_m3_ * beta_),
        critical_ratio_(bellows.valve_critical_ratio),
        subsonic_scale_(1.0 / ((1.0 - critical_ratio_) * (1.0 - critical_ratio_))),
        flow_scale_(bellows.valves_per_port * bellows.valve_conductance_m3_per_sPa * gas.reference_density_kg_per_m3) {}

  /// V_A = V0 (1 + beta q) for chamber 0, V_B = V0 (1 - beta q) for chamber 1 (m^3).
  double chamber_volume_m3(int chamber, double angle_rad) const {
    const double sign = chamber == 0 ? 1.0 : -1.0;
    return v0_m3_ * (1.0 + sign * beta_ * angle_rad);
  }

  /// Air mass in both chambers (kg), from the gas law.
  double air_mass_kg(double angle_rad, const std::array<double, 2>& chamber_Pa) const {
    return (chamber_Pa[0] * chamber_volume_m3(0, angle_rad) + chamber_Pa[1] * chamber_volume_m3(1, angle_rad)) / rt_;
  }

  /// Mass flow (kg/s) through a port's valves from `from_Pa` to `to_Pa`, signed: ISO 6358 as
  /// iso6358_mass_flow_kg_per_s (engine/model/valve_flow.hpp) times the valves per port, rearranged without
  /// a division, up psi(down / up) = sqrt(up^2 - ((down - b up) / (1 - b))^2) when not choked: the
  /// integrators evaluate it up to 16 times per right-hand side.
  double port_flow_kg_per_s(double from_Pa, double to_Pa) const {
    const bool forward = from_Pa >= to_Pa;
    const double up = forward ? from_Pa : to_Pa, down = forward ? to_Pa : from_Pa;
    if (up <= 0.0) return 0.0;
    const double excess = down - critical_ratio_ * up;  // > 0: not choked
    const double effective_up =
        excess <= 0.0 ? up : std::sqrt(std::max(0.0, up * up - subsonic_scale_ * excess * excess));
    const double magnitude = flow_scale_ * effective_up;
    return forward ? magnitude : -magnitude;
  }

  /// p_dot of chambers A and B (Pa/s): p_dot = (mdot R T - p V_dot) / V, mdot through the open
  /// valves (inlets from `supply_Pa`, outlets to ambient). The V_dot term is the bounce-back: a
  /// shrinking bellows is compressed and pushes back.
  void pressure_rates(double angle_rad, double velocity_rad_per_s, double pa_Pa, double pb_Pa,
                      const BellowsOpenings& open, double supply_Pa, double& pa_rate, double& pb_rate) const {
    const double stretch = beta_ * angle_rad;
    const double volume_a = v0_m3_ * (1.0 + stretch), volume_b = v0_m3_ * (1.0 - stretch);
    const double inverse_product = 1.0 / (volume_a * volume_b);  // one division for both chambers
    const double volume_rate_a = v0_beta_ * velocity_rad_per_s;  // V_B's is its negative
    double flow_a = 0.0, flow_b = 0.0;
    if (open.inlet[0]) flow_a += port_flow_kg_per_s(supply_Pa, pa_Pa);
    if (open.outlet[0]) flow_a -= port_flow_kg_per_s(pa_Pa, ambient_Pa_);
    if (open.inlet[1]) flow_b += port_flow_kg_per_s(supply_Pa, pb_Pa);
    if (open.outlet[1]) flow_b -= port_flow_kg_per_s(pb_Pa, ambient_Pa_);
    pa_rate = (flow_a * rt_ - pa_Pa * volume_rate_a) * (volume_b * inverse_product);
    pb_rate = (flow_b * rt_ + pb_Pa * volume_rate_a) * (volume_a * inverse_product);
  }

  double ambient_Pa() const { return ambient_Pa_; }

 private:
  double rt_ = 0.0, ambient_Pa_ = 0.0, v0_m3_ = 0.0, beta_ = 0.0, v0_beta_ = 0.0;
  double critical_ratio_ = 0.0, subsonic_scale_ = 0.0, flow_scale_ = 0.0;
};

}  // namespace bellows
