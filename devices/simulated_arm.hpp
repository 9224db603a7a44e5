// The simulated arm (spec section 4): two bellows fed by switching valves with real PWM timing,
// ISO 6358 flow, angle-dependent volumes with the full gas law, a second-order arm with creep and
// hard stops, a quantized encoder and noisy pressure sensors. Fixed internal step, deterministic
// for a given seed; its whole state can be read and written, so a run can be resumed exactly.
// RK4 at the fixed [plant] integration_step_s (0.1 ms), each step ending at the next valve edge so
// that the PWM timing is exact. Faults can be injected from another thread (a lock-free hand-over).
// One joint: its readings say joint_count 1; a command for another joint count vents it.
#pragma once

#include <array>
#include <atomic>
#include <string>
#include <cstdint>

#include "engine/model/bellows_pneumatics.hpp"
#include "engine/control/device.hpp"
#include "engine/base/gaussian_noise.hpp"
#include "engine/base/parameters.hpp"

namespace bellows {

/// Faults the simulated arm can suffer, so that every guard is tested against one it must catch.
enum class SimulatedFault : std::uint8_t {
  kNone,
  kSensorDropout,    // the sensors stop updating: readings frozen, their time too
  kStuckInlet,       // actuator A's inlet valve stays fully open whatever is commanded
  kSupplyLoss,       // the supply pressure falls to ambient
  kNanAngle,         // the encoder reads NaN
  kPressureSpike,    // chamber A's sensor reads a spike of `spike_bar` for `spike_s`
  kSwappedChambers,  // the tubes are crossed: A's valves feed and vent chamber B, and B's chamber A
  kDeadInlet,        // actuator A's inlet valve never opens whatever is commanded
};

/// Every fault, kNone first: what `[plant] fault` may name.
inline constexpr std::array<SimulatedFault, 8> kSimulatedFaults{SimulatedFault::kNone,
                                                                SimulatedFault::kSensorDropout,
                                                                SimulatedFault::kStuckInlet,
                                                                SimulatedFault::kSupplyLoss,
                                                                SimulatedFault::kNanAngle,
                                                                SimulatedFault::kPressureSpike,
                                                                SimulatedFault::kSwappedChambers,
                                                                SimulatedFault::kDeadInlet};

/// "none", "sensor-dropout", "stuck-inlet", "supply-loss", "nan-angle", "pressure-spike",
/// "swapped-chambers", "dead-inlet".
const char* to_string(SimulatedFault fault);
/// Every fault's name, in kSimulatedFaults' order, joined by ", ".
std::string simulated_fault_names();
/// Throws InputError for an unknown name.
SimulatedFault simulated_fault_from_string(const std::string& name);

class SimulatedArm final : public Device {
 public:
  /// Everything that evolves: physics, the PWM period in progress and the noise generator.
  struct State {
    double time_s = 0.0;
    double angle_rad = 0.0;
    double angular_velocity_rad_per_s = 0.0;
    double creep_rad = 0.0;  // z of the viscoelastic creep
    std::array<double, kActuatorCount> chamber_Pa{};
    double pwm_phase_s = 0.0;  // time since the current PWM period began
    JointValves command{};     // duty cycles of the current period (one joint)
    GaussianNoise::State noise{};
    SimulatedFault fault = SimulatedFault::kNone;  // active fault
    double fault_since_s = 0.0;
  };

  explicit SimulatedArm(const PlantParameters& params, std::uint64_t seed = 1);

  SensorReading read_sensors() override;
  void write_valves(const ValveCommand& command) override;
  void vent() override;
  void advance(double dt_s) override;
  bool time_follows_ticks() const override { return true; }  // in-process: physics advances per tick
  const char* name() const override { return "sim"; }

  const PlantParameters& parameters() const { return params_; }
  State state() const;
  void set_state(const State& state);

  /// Air mass in both chambers (kg), from the gas law: for conservation checks.
  double air_mass_kg() const;
  /// Volume of chamber `actuator` (m^3) at the current angle.
  double chamber_volume_m3(int actuator) const;
  /// Supply pressure currently available (Pa); a fault can lower it.
  double supply_Pa() const { return supply_Pa_; }
  void set_supply_bar(double supply_bar) { supply_Pa_ = supply_bar * 1e5; }

  /// Schedule `fault` at device time `at_s` (now, if at_s is not in the future). Safe to call from
  /// another thread than the one driving the device (a lock-free hand-over).
  void inject_fault(SimulatedFault fault, double at_s = -1.0);

 private:
  struct Physical {  // the integrated part of the state
    double angle_rad, velocity_rad_per_s, creep_rad, pa_Pa, pb_Pa;
  };
  Physical derivative(const Physical& x, const BellowsOpenings& open) const;
  void integrate(double h_s, const BellowsOpenings& open);
  BellowsDuties duties() const;
  BellowsOpenings openings_at(double phase_s) const;
  double time_to_next_switch(double phase_s) const;

  void activate_scheduled_fault();

  PlantParameters params_;
  BellowsPneumatics bellows_;  // the chambers' physics, shared with every joint of engine/model/pneumatic_arm_chain
  double supply_Pa_;
  State state_;
  GaussianNoise noise_;
  SensorReading frozen_reading_{};  // what a dropped-out sensor keeps reporting
  std::atomic<std::uint8_t> scheduled_fault_{0};
  std::atomic<double> scheduled_at_s_{0.0};
};

}  // namespace bellows
