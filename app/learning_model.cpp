#include "app/learning_model.hpp"

#include <cstdio>

#include "app/rig_profile_file.hpp"
#include "engine/base/printable_text.hpp"

namespace bellows {
namespace {

std::string model_values(const ModelParameters& m) {
  char text[160];
  std::snprintf(text, sizeof text, "kappa %g, omega0 %g, damping %g", m.kappa_rad_per_bar, m.omega0_rad_per_s,
                m.damping);
  return text;
}

bool same_identified(const ModelParameters& a, const ModelParameters& b) {
  return a.kappa_rad_per_bar == b.kappa_rad_per_bar && a.omega0_rad_per_s == b.omega0_rad_per_s &&
         a.damping == b.damping;
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
    chosen.note = "not the configuration's (" + model_values(config.model) + ")";
  }
  return chosen;
}

std::string learning_model_line(const LearningModel& chosen) {
  if (chosen.source != kModelFromRigProfile) return "";
  return "learning with the rig profile " + printable(chosen.rig_profile) + "'s [model] (" +  // a file's text
         model_values(chosen.model) + ")" + (chosen.note.empty() ? "" : ", " + chosen.note);
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
