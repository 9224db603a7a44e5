#include "app/learning_model.hpp"

#include <cstdio>

#include "app/rig_profile_file.hpp"

namespace bellows {
namespace {

bool same_identified(const ModelParameters& a, const ModelParameters& b) {
  return a.kappa_rad_per_bar == b.kappa_rad_per_bar && a.omega0_rad_per_s == b.omega0_rad_per_s && a.damping == b.damping;
}

}  // namespace

LearningModel choose_learning_model(const Configuration& config, const DeviceParameters& device) {
  LearningModel chosen;
  chosen.model = config.model;
  if (device.kind != "t7") return chosen;  // only a T7 has a rig profile
  const RigProfile profile = rig_profile_or_default(device.rig_profile);
  if (!profile.model) return chosen;
  chosen.source = kModelFromRigProfile;
  chosen.rig_profile = profile.name;
  chosen.model.kappa_rad_per_bar = profile.model->kappa_rad_per_bar;
  chosen.model.omega0_rad_per_s = profile.model->omega0_rad_per_s;
  chosen.model.damping = profile.model->damping;
  if (!same_identified(config.model, ModelParameters{}) && !same_identified(config.model, chosen.model)) {
    char line[400];
    std::snprintf(line, sizeof line,
                  "learning with the rig profile %s's [model] (kappa %g, omega0 %g, damping %g), not the "
                  "configuration's (kappa %g, omega0 %g, damping %g)",
                  profile.name.c_str(), chosen.model.kappa_rad_per_bar, chosen.model.omega0_rad_per_s, chosen.model.damping,
                  config.model.kappa_rad_per_bar, config.model.omega0_rad_per_s, config.model.damping);
    chosen.note = line;
  }
  return chosen;
}

nlohmann::ordered_json learning_model_json(const LearningModel& chosen) {
  nlohmann::ordered_json json = {{"source", chosen.source}};
  if (!chosen.rig_profile.empty()) json["rig_profile"] = chosen.rig_profile;
  json["kappa_rad_per_bar"] = chosen.model.kappa_rad_per_bar;
  json["omega0_rad_per_s"] = chosen.model.omega0_rad_per_s;
  json["damping"] = chosen.model.damping;
  return json;
}

}  // namespace bellows
