// Writing what the first day at the bench learns into the rig profile file (docs/rig-bring-up.md):
// the angle's zero and the model identified on the rig. Only the keys concerned change; the file's
// comments and everything else stay. The result is validated as any profile before it is written,
// and written atomically and durably (sessions/atomic_file.hpp): a crash leaves the old profile or
// the new one, never half of one.
#pragma once

#include <string>

#include "app/device_factory.hpp"
#include "engine/base/parameters.hpp"

namespace bellows {

/// True when `path` holds a rig profile (a TOML file with a [valves] table) rather than a bellows
/// configuration (which has none). Throws InputError when it cannot be read.
bool is_rig_profile_file(const std::string& path);

/// Sets the profile's top-level `angle_zero_rad`. Throws InputError naming the file when it is not a
/// valid profile before or would not be after.
void write_rig_profile_angle_zero(const std::string& path, double angle_zero_rad);

/// Zeroing the angle: the arm, at rest, reads `read_rad` with the zero `opened` uses now; that
/// reading becomes the zero, in the profile file at `path` and in the device from its next reading.
/// Returns what it did, for the operator: "angle_zero_rad 0.000000 -> 0.012345 (the arm read
/// +0.707 deg), written to FILE". Throws InputError when the device has no zero (not t7).
std::string zero_rig_angle(OpenedDevice& opened, const std::string& path, double read_rad);

/// Sets the profile's [model] kappa_rad_per_bar, omega0_rad_per_s and damping (the fitted ones).
void write_rig_profile_model(const std::string& path, const ModelParameters& model);

}  // namespace bellows
