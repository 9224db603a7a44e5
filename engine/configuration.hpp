// The whole configuration of an engine run, and a table that names every number in it.
// The table is the single source of section and key names: the TOML loader (app/), the session
// manifest (sessions/) and the docs all use it, so a new parameter is added in one place.
#pragma once

#include <functional>
#include <string>
#include <vector>

#include "engine/parameters.hpp"
#include "engine/safety.hpp"
#include "engine/trajectory.hpp"

namespace bellows {

struct Configuration {
  PlantParameters plant;
  ModelParameters model;
  ControllerParameters controller;
  IlcParameters ilc;
  IdentificationParameters identify;
  TimingParameters timing;
  TrajectoryLimits trajectory;
  SafetyParameters safety;
  LcmParameters lcm;
  T7Parameters t7;
};

/// What a parameter's value must satisfy.
enum class Constraint { kAny, kPositive, kNonNegative, kFraction /* in [0, 1] */ };

/// One named parameter: `[section] key`, bound to a double, an int or a string of a Configuration.
struct ParameterBinding {
  std::string section;
  std::string key;
  std::string unit;
  std::string description;
  Constraint constraint = Constraint::kAny;
  std::function<double*(Configuration&)> real;        // set for numbers
  std::function<int*(Configuration&)> integer;        // set for whole numbers
  std::function<std::string*(Configuration&)> text;   // set for names
};

/// Every parameter, in the order the docs list them.
const std::vector<ParameterBinding>& parameter_bindings();

/// Checks the constraints of every parameter and the relations between them (p_max above ambient,
/// supply above p_max, ...). Throws InputError naming `[section] key` and the offending value.
void validate_configuration(const Configuration& config);

}  // namespace bellows
