// The J-joint simulated arm's state (engine/model/pneumatic_arm_chain) as JSON, for the resume block of
// a J-joint session's manifest (`resume.device`): every double in its shortest exact form, one
// array entry per joint, and the noise generator's words as hex, so a resumed arm2/arm3 run
// continues bit for bit (as app/arm_state_json does for the single-joint arm).
#pragma once

#include <string>

#include <nlohmann/json.hpp>

#include "devices/simulated_arm_chain.hpp"

namespace bellows {

nlohmann::ordered_json chain_state_to_json(const SimulatedArmChain& arm);
/// Restores what chain_state_to_json() wrote; throws InputError (prefixed by `source`, with the
/// JSON path) for a missing or mistyped field, another joint count than the arm's, a duty outside
/// [0, 1], a pressure that is not positive or an all-zero noise generator.
void restore_chain_state(SimulatedArmChain& arm, const nlohmann::ordered_json& json, const std::string& source);

}  // namespace bellows
