// Writing what the first day at the bench learns into the rig profile file (docs/rig-bring-up.md):
// the model identified on the rig. Only the keys concerned change; the file's
// comments and everything else stay. The result is validated as any profile before it is written,
// and written atomically and durably (sessions/atomic_file.hpp): a crash leaves the old profile or
// the new one, never half of one.
#pragma once

#include <string>

#include "engine/parameters.hpp"

namespace bellows {

/// True when `path` holds a rig profile (a TOML file with a [valves] table) rather than a bellows
/// configuration (which has none). Throws InputError when it cannot be read.
bool is_rig_profile_file(const std::string& path);

/// Sets the profile's [model] kappa_rad_per_bar, omega0_rad_per_s and damping (the fitted ones).
void write_rig_profile_model(const std::string& path, const ModelParameters& model);

}  // namespace bellows
