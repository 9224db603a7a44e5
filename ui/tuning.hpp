// The values the operator may change between trials: the PID gains (sent to the engine) and the
// learning weights (the law is rebuilt). Each names the configuration key it changes.
#pragma once

#include <vector>

#include "engine/config/configuration.hpp"

namespace bellows::ui {

struct TuningField {
  const char* label;       // "k_p"
  const char* config_key;  // "[controller] k_p"
  const char* unit;        // "", "1/s", "s"
  const char* description;
  bool learning_weight;  // true: M, S, W (rebuild the law); false: a PID gain (set gains)
  double* (*value)(Configuration&);
};

const std::vector<TuningField>& tuning_fields();
double tuning_value(const Configuration& config, int field);

}  // namespace bellows::ui
