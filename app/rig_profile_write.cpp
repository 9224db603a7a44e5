#include "app/rig_profile_write.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numbers>

#include "app/rig_profile_file.hpp"
#include "app/toml_key_edit.hpp"
#include "engine/base/errors.hpp"
#include "sessions/atomic_file.hpp"

namespace bellows {
namespace {

// The new text, validated as a profile, then checked to hold what was meant (a dotted or inline key
// the line editor cannot see would otherwise win silently).
void write_profile(const std::string& path, const std::string& table,
                   const std::vector<std::pair<std::string, std::string>>& values, const std::string& comment,
                   const auto& holds_the_values) {
  const std::string text = read_file(path);
  parse_rig_profile(text, path);  // fail before changing anything
  const std::string updated = with_table_values(text, table, values, comment);
  const RigProfile written = parse_rig_profile(updated, path);
  if (!holds_the_values(written)) {
    throw InputError("rig profile " + path + ": " + (table.empty() ? values.front().first : "[" + table + "]") +
                     " could not be updated in place (dotted or inline keys?)");
  }
  write_file_atomic(path, updated);
}

bool same(double written, double meant) { return std::abs(written - meant) <= 1e-8 * std::max(1.0, std::abs(meant)); }

}  // namespace

bool is_rig_profile_file(const std::string& path) { return has_table_header(read_file(path), "valves"); }

void write_rig_profile_angle_zero(const std::string& path, double angle_zero_rad) {
  if (!std::isfinite(angle_zero_rad))
    throw InputError("rig profile " + path + ": angle_zero_rad: the angle read is not a number");
  write_profile(path, "", {{"angle_zero_rad", toml_number(angle_zero_rad)}}, "zeroed by bellows",
                [&](const RigProfile& p) { return same(p.angle_zero_rad, angle_zero_rad); });
}

std::string zero_rig_angle(OpenedDevice& opened, const std::string& path, double read_rad) {
  const std::optional<double> in_use = opened.angle_zero_rad();
  if (!in_use)
    throw InputError("this device has no angle zero to set (zeroing is for --device t7 with --rig-profile FILE)");
  const double zero_rad = *in_use + read_rad;
  write_rig_profile_angle_zero(path, zero_rad);
  opened.set_angle_zero_rad(zero_rad);
  char text[400];
  std::snprintf(text, sizeof text, "angle_zero_rad %.6f -> %.6f (the arm read %+.3f deg), written to %s", *in_use,
                zero_rad, read_rad * 180.0 / std::numbers::pi, path.c_str());
  return text;
}

void write_rig_profile_model(const std::string& path, const ModelParameters& model) {
  write_profile(path, "model",
                {{"kappa_rad_per_bar", toml_number(model.kappa_rad_per_bar)},
                 {"omega0_rad_per_s", toml_number(model.omega0_rad_per_s)},
                 {"damping", toml_number(model.damping)}},
                "fitted by bellows identify", [&](const RigProfile& p) {
                  return p.model && same(p.model->kappa_rad_per_bar, model.kappa_rad_per_bar) &&
                         same(p.model->omega0_rad_per_s, model.omega0_rad_per_s) &&
                         same(p.model->damping, model.damping);
                });
}

}  // namespace bellows
