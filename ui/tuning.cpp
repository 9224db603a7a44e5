#include "ui/tuning.hpp"

namespace bellows::ui {

const std::vector<TuningField>& tuning_fields() {
  static const std::vector<TuningField> fields = {
      {"k_ff", "[controller] k_ff", "", "feed-forward gain", false,
       [](Configuration& c) { return &c.controller.k_ff; }},
      {"k_p", "[controller] k_p", "", "proportional gain", false, [](Configuration& c) { return &c.controller.k_p; }},
      {"k_i", "[controller] k_i", "1/s", "integral gain", false,
       [](Configuration& c) { return &c.controller.k_i_per_s; }},
      {"k_d", "[controller] k_d", "s", "derivative gain (on the measured velocity)", false,
       [](Configuration& c) { return &c.controller.k_d_s; }},
      {"M", "[ilc] m", "", "weight of the tracking error", true, [](Configuration& c) { return &c.ilc.m; }},
      {"S", "[ilc] s", "", "weight of the change of the correction", true, [](Configuration& c) { return &c.ilc.s; }},
      {"W", "[ilc] w", "", "weight of the correction's rate (smoothness)", true,
       [](Configuration& c) { return &c.ilc.w; }},
  };
  return fields;
}

double tuning_value(const Configuration& config, int field) {
  Configuration copy = config;
  return *tuning_fields()[static_cast<std::size_t>(field)].value(copy);
}

}  // namespace bellows::ui
