#include "app/arm_state_json.hpp"

#include "engine/base/errors.hpp"
#include "sessions/json_reader.hpp"
#include "engine/base/units.hpp"

namespace bellows {
namespace {

template <std::size_t Size>
nlohmann::ordered_json pair_to_json(const std::array<double, Size>& values) {
  nlohmann::ordered_json out = nlohmann::ordered_json::array();
  for (double value : values) out.push_back(value);
  return out;
}

template <std::size_t Size>
std::array<double, Size> pair_from_json(const JsonReader& r) {
  if (r.size() != Size) r.fail("expected " + std::to_string(Size) + " numbers");
  std::array<double, Size> out{};
  for (std::size_t i = 0; i < Size; ++i) out[i] = r[i].number();
  return out;
}
}  // namespace

nlohmann::ordered_json arm_state_to_json(const SimulatedArm& arm) {
  const SimulatedArm::State s = arm.state();
  nlohmann::ordered_json noise = nlohmann::ordered_json::array();
  for (std::uint64_t word : s.noise) noise.push_back(hex_word(word));
  return {{"time_s", s.time_s},
          {"angle_rad", s.angle_rad},
          {"angular_velocity_rad_per_s", s.angular_velocity_rad_per_s},
          {"creep_rad", s.creep_rad},
          {"chamber_Pa", pair_to_json(s.chamber_Pa)},
          {"pwm_phase_s", s.pwm_phase_s},
          {"inlet_duty", pair_to_json(s.command.inlet_duty)},
          {"outlet_duty", pair_to_json(s.command.outlet_duty)},
          {"noise_state", noise},
          {"fault", to_string(s.fault)},
          {"fault_since_s", s.fault_since_s},
          {"supply_Pa", arm.supply_Pa()}};
}

void restore_arm_state(SimulatedArm& arm, const nlohmann::ordered_json& json, const std::string& source) {
  const JsonReader r(json, source, "/resume/device");
  SimulatedArm::State s;
  s.time_s = r["time_s"].number();
  s.angle_rad = r["angle_rad"].number();
  s.angular_velocity_rad_per_s = r["angular_velocity_rad_per_s"].number();
  s.creep_rad = r["creep_rad"].number();
  s.chamber_Pa = pair_from_json<kActuatorCount>(r["chamber_Pa"]);
  s.pwm_phase_s = r["pwm_phase_s"].number();
  s.command.inlet_duty = pair_from_json<kActuatorCount>(r["inlet_duty"]);
  s.command.outlet_duty = pair_from_json<kActuatorCount>(r["outlet_duty"]);
  const JsonReader noise = r["noise_state"];
  if (noise.size() != s.noise.size()) noise.fail("expected " + std::to_string(s.noise.size()) + " words");
  for (std::size_t i = 0; i < s.noise.size(); ++i) s.noise[i] = noise[i].hex_word();
  if (s.noise == GaussianNoise::State{}) noise.fail("an all-zero generator state never changes; it cannot be right");
  for (double duty :
       {s.command.inlet_duty[0], s.command.inlet_duty[1], s.command.outlet_duty[0], s.command.outlet_duty[1]}) {
    if (duty < 0.0 || duty > 1.0) r.fail("a duty cycle is outside [0, 1]");
  }
  for (double pressure : s.chamber_Pa) {
    if (!(pressure > 0.0)) r["chamber_Pa"].fail("pressures must be positive");
  }
  // The first session format (1afa6a9) saved the arm before it could be given a fault: without
  // "fault" and "fault_since_s", none is active (State's defaults).
  if (r.has("fault") || r.has("fault_since_s")) {
    try {
      s.fault = simulated_fault_from_string(r["fault"].text());
    } catch (const InputError& error) {
      r["fault"].fail(error.what());
    }
    s.fault_since_s = r["fault_since_s"].number();
  }
  const double supply_Pa = r["supply_Pa"].number();
  if (!(supply_Pa > 0.0)) r["supply_Pa"].fail("must be positive");
  arm.set_state(s);
  // The arm is rebuilt from the same configuration: only a changed supply (a fault) needs setting.
  if (supply_Pa != arm.supply_Pa()) arm.set_supply_bar(supply_Pa / kPaPerBar);
}

}  // namespace bellows
