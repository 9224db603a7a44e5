// Which model the learning uses (docs/rig-bring-up.md, "Identify the model"). A rig profile with a
// [model] (identified on that rig: `bellows identify --write-model PROFILE`) describes the arm the
// run drives: its kappa, omega0 and damping are used. Otherwise the configuration's [model] is. The
// rest of [model] (volume_gain) is always the configuration's. `bellows run` and the console choose
// here; the session records the model in its configuration and where it came from (`model_source`).
#pragma once

#include <string>

#include <nlohmann/json.hpp>

#include "engine/config/configuration.hpp"

namespace bellows {

/// The manifest's model sources.
inline constexpr const char* kModelFromConfiguration = "configuration";
inline constexpr const char* kModelFromRigProfile = "rig_profile";

struct LearningModel {
  ModelParameters model;
  std::string source = kModelFromConfiguration;  // kModelFromConfiguration or kModelFromRigProfile
  std::string rig_profile;                       // the profile's name when it came from one
  /// Not empty when the configuration sets a kappa, omega0 or damping of its own (not the defaults)
  /// that the rig profile's model replaces: "not the configuration's (kappa 8.2, ...)", so that the
  /// replacement is never silent (learning_model_line()).
  std::string note;
};

/// The model for a run on `device` (resolved: kind and rig profile) with `config`. Reads the rig
/// profile of a t7 (the built-in paper rig's when none is named; InputError for a bad one).
LearningModel choose_learning_model(const Configuration& config, const DeviceParameters& device);

/// For the operator, when the model is not the configuration's: "learning with the rig profile
/// my-rig's [model] (kappa 6.5, omega0 12, damping 0.4)", with ", not the configuration's (...)" when
/// it replaces one the configuration set; "" when it is the configuration's.
std::string learning_model_line(const LearningModel& chosen);

/// {"source", "rig_profile" (with that source), "kappa_rad_per_bar", "omega0_rad_per_s", "damping"}
nlohmann::ordered_json learning_model_json(const LearningModel& chosen);

}  // namespace bellows
