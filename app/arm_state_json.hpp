// The simulated arm's state as JSON, for the resume block of a session manifest: every double in
// its shortest exact form and the noise generator's words as hex, so a resumed run continues bit
// for bit.
#pragma once

#include <string>

#include <nlohmann/json.hpp>

#include "devices/simulated_arm.hpp"

namespace bellows {

nlohmann::ordered_json arm_state_to_json(const SimulatedArm& arm);
/// Restores what arm_state_to_json() wrote; throws InputError (prefixed by `source`) naming the field.
void restore_arm_state(SimulatedArm& arm, const nlohmann::ordered_json& json, const std::string& source);

}  // namespace bellows
