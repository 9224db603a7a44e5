// `bellows identify` on an arm of several joints (an [arm] chain; docs/rig-bring-up.md, "Identify an
// arm of several joints"): per joint k, a trial with joint k's reference excited (the [identify]
// signal) while every other joint's PID holds its start angle, then the same with the held-out
// signal. From those trials (engine/operator/coupled_identification):
//  - each joint's single-joint model (kappa, omega0, delta) by the single-joint fit on its trial;
//  - the coupled model (2J states: the chain linearization's structure and order), from the J
//    identification trials together, every joint's response to every joint's excitation;
// each validated on the held-out trials and compared with the chain's linearization stretched out
// (the `coupled` model of the learning). `--write-model FILE` (a configuration) receives the coupled
// model as [identified_joint1..J] and `[ilc] joint_model = "identified"`, which a run then learns with.
#pragma once

#include <iosfwd>
#include <string>

#include "app/identify_command.hpp"
#include "engine/config/configuration.hpp"

namespace bellows {

/// `config` has an [arm] chain. `write_model_text`: the existing text of options.write_model_path
/// ("" when it does not exist yet). Throws InputError (a rig profile to write into, a device that
/// cannot drive the arm), EnvironmentError, EngineFault, Cancelled as identify_command does.
int identify_chain_command(const IdentifyOptions& options, const Configuration& config,
                           const std::string& write_model_text, std::ostream& out, std::ostream& progress);

/// `toml_text` with [identified_joint1..J] set to `identified`'s first J rows and [ilc] joint_model =
/// "identified", everything else kept (app/toml_key_edit). Checked as a configuration (InputError
/// naming `source_name`).
std::string with_identified_model(const std::string& toml_text, const std::string& source_name,
                                  const IdentifiedArmParameters& identified, int joints);

}  // namespace bellows
