// `bellows identify`: an identification trial on the device, a least-squares fit of kappa, omega0
// and delta, a held-out validation trial with the other excitation, and optionally the fitted values
// written into a config file's or a rig profile's [model] section. All of it recorded in a session.
#pragma once

#include <cstdint>
#include <iosfwd>
#include <string>

#include "app/device_factory.hpp"
#include "engine/config/configuration.hpp"
#include "engine/rt/realtime_loop.hpp"

namespace bellows {

struct IdentifyOptions {
  std::string config_path;
  std::string signal;  // overrides [identify] signal when set
  std::uint64_t seed = 1;
  bool json = false;
  std::string write_model_path;  // a config file's [model], or a rig profile's (a file with [valves]), receives the fit
  bool force = false;            // --force: replace a model write_model_path holds already (model_held_in)
  DeviceOptions device;          // --device, --lcm, --t7, --rig-profile over [device]
  RealtimeMode rt = RealtimeMode::kTry;  // the engine loop on a rig (lcm, t7)
  // Recorded in a session like a run (app/identify_session) unless no_save.
  bool no_save = false;
  std::string data_dir;      // empty: the default sessions folder
  std::string session_name;  // empty: start time and the excitation's name
};

int identify_command(const IdentifyOptions& options, std::ostream& out, std::ostream& progress);

/// The model `toml_text` (a valid configuration or rig profile) holds already, which --write-model
/// would replace, in words ("[model] kappa = 7.2, omega0 = 13.2, damping = 0.197"; several joints:
/// "[identified_joint1], [identified_joint2]"), or "" when it holds none. Other keys are not a model.
std::string model_held_in(const std::string& toml_text, bool rig_profile, bool several_joints);

/// --write-model's rule, before any trial runs: a file that does not exist is created; one that
/// exists gets the model added, the rest of it kept; one that holds a model already
/// (model_held_in) is refused without --force ("... holds a model already (...): --force replaces
/// it"), so that an identification never silently replaces an earlier one.
void check_write_model_target(const IdentifyOptions& options, const std::string& toml_text, bool exists,
                              bool rig_profile, bool several_joints);

/// `toml_text` with [model] kappa, omega0 and damping set to `model`: existing keys are replaced in
/// place, missing ones added, everything else (comments, order, other sections) kept. The result is
/// checked as a configuration; throws InputError naming `source_name` if it is not valid.
std::string with_model_section(const std::string& toml_text, const std::string& source_name,
                               const ModelParameters& model);

}  // namespace bellows
