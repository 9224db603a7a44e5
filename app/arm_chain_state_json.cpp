#include "app/arm_chain_state_json.hpp"

#include <cstddef>

#include "engine/base/errors.hpp"
#include "sessions/json_reader.hpp"
#include "engine/base/units.hpp"

namespace bellows {
namespace {

using Json = nlohmann::ordered_json;

Json joint_values(const JointVector& values) {
  Json out = Json::array();
  for (Eigen::Index j = 0; j < values.size(); ++j) out.push_back(values(j));
  return out;
}

/// One array of `joints` entries (the path says which field when it is not).
JsonReader joint_array(const JsonReader& r, const char* key, int joints) {
  JsonReader array = r[key];  // not const: returned by move
  if (array.size() != static_cast<std::size_t>(joints)) {
    array.fail("expected " + std::to_string(joints) + " entries, one per joint of the arm, found " +
               std::to_string(array.size()));
  }
  return array;
}

JointVector joint_values_from(const JsonReader& r, const char* key, int joints) {
  const JsonReader array = joint_array(r, key, joints);
  JointVector out(joints);
  for (int j = 0; j < joints; ++j) out(j) = array[static_cast<std::size_t>(j)].number();
  return out;
}

std::array<double, 2> pair_from(const JsonReader& r) {
  if (r.size() != 2) r.fail("expected 2 numbers (A, B)");
  return {r[0].number(), r[1].number()};
}

}  // namespace

Json chain_state_to_json(const SimulatedArmChain& arm) {
  const PneumaticArmChain::State s = arm.chain().state();
  const auto joints = static_cast<std::size_t>(arm.joints());
  Json chambers = Json::array(), inlets = Json::array(), outlets = Json::array();
  for (std::size_t j = 0; j < joints; ++j) {
    chambers.push_back({s.chamber_Pa[j][0], s.chamber_Pa[j][1]});
    inlets.push_back({s.duties[j].inlet[0], s.duties[j].inlet[1]});
    outlets.push_back({s.duties[j].outlet[0], s.duties[j].outlet[1]});
  }
  Json noise = Json::array();
  for (std::uint64_t word : s.noise) noise.push_back(hex_word(word));
  return {{"joints", arm.joints()},
          {"time_s", s.time_s},
          {"angle_rad", joint_values(s.angle_rad)},
          {"velocity_rad_per_s", joint_values(s.velocity_rad_per_s)},
          {"creep_rad", joint_values(s.creep_rad)},
          {"chamber_Pa", chambers},
          {"pwm_phase_s", s.pwm_phase_s},
          {"inlet_duty", inlets},
          {"outlet_duty", outlets},
          {"noise_state", noise},
          {"supply_Pa", arm.chain().supply_Pa()}};
}

void restore_chain_state(SimulatedArmChain& arm, const Json& json, const std::string& source) {
  const JsonReader r(json, source, "/resume/device");
  r.expect_object();
  const int joints = arm.joints();
  if (r["joints"].integer(1, kMaxJoints) != joints) {
    r["joints"].fail("the session's arm has " + std::to_string(r["joints"].json().get<int>()) + " joints, this arm " +
                     std::to_string(joints));
  }
  PneumaticArmChain::State s = arm.chain().state();  // the slots beyond the arm's joints as they are
  s.time_s = r["time_s"].number();
  s.angle_rad = joint_values_from(r, "angle_rad", joints);
  s.velocity_rad_per_s = joint_values_from(r, "velocity_rad_per_s", joints);
  s.creep_rad = joint_values_from(r, "creep_rad", joints);
  const JsonReader chambers = joint_array(r, "chamber_Pa", joints);
  const JsonReader inlets = joint_array(r, "inlet_duty", joints);
  const JsonReader outlets = joint_array(r, "outlet_duty", joints);
  for (std::size_t j = 0; j < static_cast<std::size_t>(joints); ++j) {
    s.chamber_Pa[j] = pair_from(chambers[j]);
    s.duties[j].inlet = pair_from(inlets[j]);
    s.duties[j].outlet = pair_from(outlets[j]);
    for (double pressure : s.chamber_Pa[j]) {
      if (!(pressure > 0.0)) chambers[j].fail("pressures must be positive");
    }
    for (double duty : {s.duties[j].inlet[0], s.duties[j].inlet[1], s.duties[j].outlet[0], s.duties[j].outlet[1]}) {
      if (!(duty >= 0.0 && duty <= 1.0))
        r.fail("a duty cycle of joint " + std::to_string(j + 1) + " is outside [0, 1]");
    }
  }
  s.pwm_phase_s = r["pwm_phase_s"].number();
  const JsonReader noise = r["noise_state"];
  if (noise.size() != s.noise.size()) noise.fail("expected " + std::to_string(s.noise.size()) + " words");
  for (std::size_t i = 0; i < s.noise.size(); ++i) s.noise[i] = noise[i].hex_word();
  if (s.noise == GaussianNoise::State{}) noise.fail("an all-zero generator state never changes; it cannot be right");
  const double supply_Pa = r["supply_Pa"].number();
  if (!(supply_Pa > 0.0)) r["supply_Pa"].fail("must be positive");
  arm.chain().set_state(s);
  // The arm is rebuilt from the same configuration: only a changed supply needs setting (through
  // bar, which may round: the chain keeps its supply in Pa but takes it in bar).
  if (supply_Pa != arm.chain().supply_Pa()) arm.chain().set_supply_bar(supply_Pa / kPaPerBar);
}

}  // namespace bellows
