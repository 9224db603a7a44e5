// The bellows of one joint (reference-system.md section 4): chambers A and B, each filled from the
// supply by its inlet valves and emptied to ambient by its outlet valves (switching valves with real
// PWM timing, ISO 6358 flow), their volumes depending on the joint's angle, with the full gas law.
// One implementation for the single-joint simulated arm (devices/simulated_arm) and every joint of the
// J-joint one (engine/pneumatic_arm_chain): the same physics per joint. Inline: it is the inner loop
// of both integrators (four right-hand sides per 0.1 ms step).
#pragma once

#include <algorithm>
#include <array>

#include "engine/parameters.hpp"
#include "engine/valve_flow.hpp"

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
        conductance_(bellows.valve_conductance_m3_per_sPa),
        critical_ratio_(bellows.valve_critical_ratio),
        density_(gas.reference_density_kg_per_m3),
        valves_(bellows.valves_per_port) {}

  /// V_A = V0 (1 + beta q) for chamber 0, V_B = V0 (1 - beta q) for chamber 1 (m^3).
  double chamber_volume_m3(int chamber, double angle_rad) const {
    const double sign = chamber == 0 ? 1.0 : -1.0;
    return v0_m3_ * (1.0 + sign * beta_ * angle_rad);
  }

  /// Air mass in both chambers (kg), from the gas law.
  double air_mass_kg(double angle_rad, const std::array<double, 2>& chamber_Pa) const {
    return (chamber_Pa[0] * chamber_volume_m3(0, angle_rad) + chamber_Pa[1] * chamber_volume_m3(1, angle_rad)) / rt_;
  }

  /// p_dot of chambers A and B (Pa/s): p_dot = mdot R T / V - p V_dot / V, mdot through the open
  /// valves (inlets from `supply_Pa`, outlets to ambient). The second term is the bounce-back: a
  /// shrinking bellows is compressed and pushes back.
  void pressure_rates(double angle_rad, double velocity_rad_per_s, double pa_Pa, double pb_Pa,
                      const BellowsOpenings& open, double supply_Pa, double& pa_rate, double& pb_rate) const {
    pa_rate = chamber_rate(1.0, angle_rad, velocity_rad_per_s, pa_Pa, open.inlet[0], open.outlet[0], supply_Pa);
    pb_rate = chamber_rate(-1.0, angle_rad, velocity_rad_per_s, pb_Pa, open.inlet[1], open.outlet[1], supply_Pa);
  }

  double ambient_Pa() const { return ambient_Pa_; }

 private:
  double chamber_rate(double sign, double angle_rad, double velocity_rad_per_s, double chamber_Pa, bool inlet,
                      bool outlet, double supply_Pa) const {
    const double volume = v0_m3_ * (1.0 + sign * beta_ * angle_rad);
    const double volume_rate = sign * v0_beta_ * velocity_rad_per_s;
    double mass_flow = 0.0;
    if (inlet) mass_flow += valves_ * iso6358_mass_flow_kg_per_s(supply_Pa, chamber_Pa, conductance_, critical_ratio_, density_);
    if (outlet) mass_flow -= valves_ * iso6358_mass_flow_kg_per_s(chamber_Pa, ambient_Pa_, conductance_, critical_ratio_, density_);
    return mass_flow * rt_ / volume - chamber_Pa * volume_rate / volume;
  }

  double rt_ = 0.0, ambient_Pa_ = 0.0, v0_m3_ = 0.0, beta_ = 0.0, v0_beta_ = 0.0;
  double conductance_ = 0.0, critical_ratio_ = 0.0, density_ = 0.0;
  int valves_ = 0;
};

}  // namespace bellows
