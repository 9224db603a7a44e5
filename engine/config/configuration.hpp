// The whole configuration of an engine run, and a table that names every number in it.
// The table is the single source of section and key names: the TOML loader (app/), the session
// manifest (sessions/) and the docs all use it, so a new parameter is added in one place.
#pragma once

#include <functional>
#include <string>
#include <vector>

#include "engine/base/parameters.hpp"
#include "engine/control/safety.hpp"
#include "engine/trial/trajectory.hpp"

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
  DeviceParameters device;
  ArmParameters arm;
  RigCheckParameters rig_check;
  T7Parameters t7;
  IdentifiedArmParameters identified;  // last: aggregate initializers of the others keep their order
};

/// The values a number may take: [min, max], either end open. Every key has one, documented in
/// docs/configuration.md; the loader, the manifest reader and validate_configuration() all use it.
struct Range {
  double min = 0.0;
  double max = 0.0;
  bool min_open = false;  // (min, ...: min itself is refused
  bool max_open = false;  // ..., max): max itself is refused
  bool contains(double value) const {
    return (min_open ? value > min : value >= min) && (max_open ? value < max : value <= max);
  }
  /// "[0, 1)", "(0, 100]": as the docs show it.
  std::string text() const;
};

/// One named parameter: `[section] key`, bound to a double, an int or a string of a Configuration.
struct ParameterBinding {
  std::string section;
  std::string key;
  std::string unit;
  std::string description;
  Range range;                                       // numbers and whole numbers only
  std::function<double*(Configuration&)> real;       // set for numbers
  std::function<int*(Configuration&)> integer;       // set for whole numbers
  std::function<std::string*(Configuration&)> text;  // set for names
};

/// Every parameter, in the order the docs list them.
const std::vector<ParameterBinding>& parameter_bindings();

/// The binding of `[section] key`, or nullptr when there is none.
const ParameterBinding* find_parameter(const std::string& section, const std::string& key);

/// Checks a value read for `binding` (from TOML or a manifest) before it is stored: finite, inside
/// the range and, for a whole number, exactly a whole number (never wrapped into an int).
/// Throws InputError "[section] key = value: must be in [min, max]".
void check_parameter_value(const ParameterBinding& binding, double value);

/// Checks the range of every parameter, the relations between them (p_max above ambient, supply
/// above p_max, ...) and the memory and time the configuration implies (engine/config/configuration_cost),
/// before anything is allocated. Throws InputError naming `[section] key` and the offending value.
void validate_configuration(const Configuration& config);

}  // namespace bellows
