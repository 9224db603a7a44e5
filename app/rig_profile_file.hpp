// Reading a rig profile (devices/rig_profile.hpp) from TOML. Every key must be known, of the right
// type and valid; anything else is an InputError naming the file and the key (exit status 2).
#pragma once

#include <string>

#include "devices/rig_profile.hpp"

namespace bellows {

/// Parses and validates profile text; `source_name` names it in messages.
RigProfile parse_rig_profile(const std::string& toml_text, const std::string& source_name);
/// Reads and validates a profile file.
RigProfile load_rig_profile(const std::string& path);
/// The paper rig's profile (profiles/paper-rig.toml, built into the binary): the default.
RigProfile paper_rig_profile();
/// The text of profiles/paper-rig.toml as built in.
const std::string& paper_rig_profile_text();
/// `path` empty: the paper rig's profile; else load_rig_profile(path).
RigProfile rig_profile_or_default(const std::string& path);

}  // namespace bellows
