// Every key of the parameter table has a range, and the TOML loader and the session manifest reader
// both refuse a value outside it, NaN, a value of the wrong type and a whole number that would wrap,
// naming the file and the key. The memory and time a configuration implies are bounded too.
#include <gtest/gtest.h>

#include <atomic>
#include <cmath>
#include <sstream>
#include <string>
#include <vector>

#include "app/config_file.hpp"
#include "engine/config/configuration_cost.hpp"
#include "engine/config/convergence.hpp"
#include "engine/base/errors.hpp"
#include "engine/operator/identification.hpp"
#include "engine/config/learning_law_factory.hpp"
#include "engine/model/arm_model.hpp"
#include "sessions/manifest_json.hpp"
#include "tests/config_test_support.hpp"

namespace bellows {
namespace {

std::string literal(double value) {
  if (std::isnan(value)) return "nan";
  std::ostringstream out;
  out.precision(17);
  out << value;
  std::string text = out.str();
  if (text.find_first_of(".e") == std::string::npos && text.find("inf") == std::string::npos) text += ".0";
  return text;
}

// The values every number key must refuse, as TOML literals with what the error must say.
struct BadValue {
  std::string toml;
  double json;  // the same value for the manifest (NaN: the manifest writes null; skipped there)
  std::string why;
};

std::vector<BadValue> bad_values(const ParameterBinding& b) {
  const Range& r = b.range;
  std::vector<BadValue> bad;
  if (b.integer) {
    const long long low = static_cast<long long>(r.min) - 1, high = static_cast<long long>(r.max) + 1;
    bad.push_back({std::to_string(low), static_cast<double>(low), "below the range"});
    bad.push_back({std::to_string(high), static_cast<double>(high), "above the range"});
    // Whole numbers that an int would wrap into the default or into 1..3.
    for (const long long wrap : {4294967296LL + 3, 4294967296LL + 1, -4294967296LL + 2, 9223372036854775807LL}) {
      bad.push_back({std::to_string(wrap), static_cast<double>(wrap), "wraps"});
    }
    bad.push_back({"2.5", 2.5, "a fraction"});
    bad.push_back({"nan", NAN, "NaN"});
  } else {
    const double below = r.min_open ? r.min : r.min - std::max(std::abs(r.min) * 0.5, 1e-300);
    const double above = r.max_open ? r.max : r.max + std::max(std::abs(r.max), 1.0);
    bad.push_back({literal(below), below, "below the range"});
    bad.push_back({literal(above), above, "above the range"});
    bad.push_back({"nan", NAN, "NaN"});
    bad.push_back({"inf", INFINITY, "infinity"});
    bad.push_back({"-inf", -INFINITY, "minus infinity"});
  }
  bad.push_back({"\"x\"", NAN, "a string"});
  return bad;
}

TEST(ConfigBounds, EveryNumberKeyHasARangeHoldingItsDefault) {
  Configuration defaults;
  for (const ParameterBinding& b : parameter_bindings()) {
    if (b.text) continue;
    const double value = b.real ? *b.real(defaults) : *b.integer(defaults);
    EXPECT_TRUE(b.range.contains(value)) << "[" << b.section << "] " << b.key << " default " << value << " outside "
                                         << b.range.text();
    EXPECT_LT(b.range.min, b.range.max) << b.key;
    EXPECT_TRUE(std::isfinite(b.range.min) && std::isfinite(b.range.max)) << b.key;
  }
  EXPECT_NO_THROW(validate_configuration(defaults));
}

TEST(ConfigBounds, TheLoaderRefusesEveryBadValueOfEveryKeyNamingFileAndKey) {
  int checked = 0;
  for (const ParameterBinding& b : parameter_bindings()) {
    std::vector<BadValue> bad =
        b.text ? std::vector<BadValue>{{"3", 3, "a number"}, {"nan", NAN, "NaN"}} : bad_values(b);
    for (const BadValue& v : bad) {
      const std::string toml = "[" + b.section + "]\n" + b.key + " = " + v.toml + "\n";
      Configuration config;
      try {
        apply_config_toml(toml, "lab.toml", config);
        ADD_FAILURE() << "accepted (" << v.why << "): " << toml;
      } catch (const InputError& e) {
        const std::string what = e.what();
        EXPECT_NE(what.find("lab.toml"), std::string::npos) << what;
        EXPECT_NE(what.find("[" + b.section + "] " + b.key), std::string::npos) << v.why << ": " << what;
        EXPECT_EQ(what.find('\n'), std::string::npos) << "one line: " << what;
      }
      ++checked;
    }
  }
  EXPECT_GT(checked, 5 * static_cast<int>(parameter_bindings().size()));
}

TEST(ConfigBounds, TheRangeEndsThemselvesAreAcceptedOrRefusedAsDocumented) {
  // Each end alone, on top of the defaults: a closed end passes the key's own check (a relation with
  // another key or a cost budget may still refuse it, and must then name something else).
  for (const ParameterBinding& b : parameter_bindings()) {
    if (b.text) continue;
    for (const bool low : {true, false}) {
      const double end = low ? b.range.min : b.range.max;
      const bool open = low ? b.range.min_open : b.range.max_open;
      try {
        check_parameter_value(b, end);
        EXPECT_FALSE(open) << "[" << b.section << "] " << b.key << " = " << end << " accepted at an open end";
      } catch (const InputError& e) {
        EXPECT_TRUE(open) << e.what();
      }
    }
  }
}

TEST(ConfigBounds, TheManifestReaderRefusesTheSameValues) {
  const nlohmann::ordered_json good = configuration_to_json(Configuration{});
  EXPECT_NO_THROW(configuration_from_json(JsonReader(good, "manifest.json")));
  for (const ParameterBinding& b : parameter_bindings()) {
    if (b.text) continue;
    for (const BadValue& v : bad_values(b)) {
      if (std::isnan(v.json) || std::isinf(v.json)) continue;  // JSON has neither: written as null, a wrong type
      nlohmann::ordered_json json = good;
      if (b.integer && v.json == std::floor(v.json)) json[b.section][b.key] = static_cast<long long>(v.json);
      else json[b.section][b.key] = v.json;
      try {
        configuration_from_json(JsonReader(json, "manifest.json"));
        ADD_FAILURE() << "manifest accepted [" << b.section << "] " << b.key << " = " << v.toml;
      } catch (const InputError& e) {
        const std::string what = e.what();
        EXPECT_NE(what.find("manifest.json"), std::string::npos) << what;
        EXPECT_NE(what.find(b.key), std::string::npos) << what;
      }
    }
  }
}

using testing::expect_config_refused;

TEST(ConfigBounds, TheIssuesHugeValuesAreRefused) {
  expect_config_refused("[timing]\ntick_s = 1e-9\n", "[timing] tick_s");
  expect_config_refused("[safety]\nblack_box_s = 1e9\n", "[safety] black_box_s");
  expect_config_refused("[plant]\nintegration_step_s = 1e-12\n", "[plant] integration_step_s");
  expect_config_refused("[ilc]\nprediction_grid_points = 100000\n", "[ilc] prediction_grid_points");
  expect_config_refused("[safety]\nstale_ticks = 4294967299\n", "[safety] stale_ticks");
  expect_config_refused("[timing]\nticks_per_sample = 4294967297\n", "[timing] ticks_per_sample");
  expect_config_refused("[timing]\nsettle_s = 1e9\n", "[timing] settle_s");
}

TEST(ConfigBounds, CombinationsOverACostBudgetAreRefusedNamingTheKeys) {
  // Each value is in its own range; together they would allocate or compute far too much.
  expect_config_refused("[timing]\ntick_s = 1e-4\n[safety]\nblack_box_s = 60.0\n", "black_box_s");
  expect_config_refused("[timing]\ntick_s = 1.0\n[plant]\npwm_period_s = 1.0\nintegration_step_s = 1e-6\n",
                        "integration_step_s");
  expect_config_refused("[timing]\ntick_s = 1e-4\n[identify]\nduration_s = 600.0\n", "[identify] duration_s");
  expect_config_refused(
      "[timing]\ntick_s = 1e-4\nsettle_s = 60.0\n[safety]\nblack_box_s = 1.0\n[identify]\nduration_s = 50.0\n",
      "[identify] duration_s");
  // A law whose Q-filter is at or above the Nyquist frequency is refused at load, naming the file.
  expect_config_refused("[ilc]\nlaw = \"pd\"\npd_q_cutoff_hz = 30.0\n", "[ilc] pd_q_cutoff_hz");
  expect_config_refused("[ilc]\nlaw = \"p-type\"\n", "[ilc] law");
  expect_config_refused("[safety]\nsensor_min_bar = 12.0\n", "[safety] sensor_min_bar");
  expect_config_refused("[identify]\nchirp_start_hz = 5.0\n", "[identify] chirp_start_hz");
  expect_config_refused("[identify]\namplitude_deg = 70.0\n", "[identify] amplitude_deg");
  expect_config_refused("[ilc]\nlaw = \"noilc-dense\"\ns = 0.0\nw = 0.0\n", "[ilc] s, w");
  expect_config_refused("[identify]\nsignal = \"noise\"\n", "[identify] signal");
}

TEST(ConfigBounds, ATrialOverItsBudgetIsRefusedBeforeTheLawIsBuilt) {
  Configuration config;
  EXPECT_NO_THROW(check_trial_cost(config, 400));
  EXPECT_THROW(check_trial_cost(config, cost_budget::kMaxTicksPerTrial), InputError);
  EXPECT_THROW(check_trial_cost(config, 2'000'000'000), InputError);  // no overflow into a small count
  config.ilc.law = "noilc-constrained";
  config.ilc.admm_max_iterations = 100000;
  EXPECT_NO_THROW(check_trial_cost(config, 400));
  EXPECT_THROW(check_trial_cost(config, 10000), InputError);  // 10^9 ADMM sweeps per update
  config = {};
  config.ilc.law = "noilc-dense";
  const DiscreteArmModel model = discretize_arm_model(config.model, config.timing.sample_s());
  try {
    make_learning_law(config, model, cost_budget::kMaxDenseLawSamples + 1);
    ADD_FAILURE() << "noilc-dense built beyond its budget";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("noilc-dense"), std::string::npos) << e.what();
  }
}

TEST(ConfigBounds, DeeplyNestedOrHugeFilesAreRefusedBeforeParsing) {
  std::string header = "[a";
  while (header.size() < 100000) header += ".a";
  expect_config_refused(header + ".b]\nx = 1\n", "nested deeper");
  expect_config_refused("[plant]\nkappa = " + std::string(50000, '[') + std::string(50000, ']') + "\n",
                        "nested deeper");
  std::string inline_tables = "x = ";
  for (int i = 0; i < 50000; ++i) inline_tables += "{a=";
  expect_config_refused(inline_tables + "1" + std::string(50000, '}') + "\n", "nested deeper");
  expect_config_refused("[plant]\n" + std::string(300000, '#') + "\n", "larger than");
  // Brackets and dots inside strings and comments are not nesting.
  Configuration config;
  EXPECT_NO_THROW(
      apply_config_toml("# [a.b.c.d.e.f.g.h.i.j.k.l.m.n.o.p.q.r.s.t]\n[lcm]\n"
                        "key_file = \"[[[[[[[[[[[[[[[[[[[[.......\\\"{{{{{{{{{{{{{{{{{\"  # {{{{{{{{{{{{{{{{{{{{\n"
                        "[ilc]\nlaw = 'noilc'\n",
                        "lab.toml", config));
  EXPECT_EQ(config.lcm.key_file, "[[[[[[[[[[[[[[[[[[[[.......\"{{{{{{{{{{{{{{{{{");
}

TEST(Cancellation, LongComputationsStopWhenTheirFlagIsSet) {
  const std::atomic<bool> stop{true};
  const Configuration config;
  const DiscreteArmModel model = discretize_arm_model(config.model, config.timing.sample_s());
  const std::unique_ptr<LearningLaw> law = make_learning_law(config, model, 400);
  EXPECT_THROW(predict_convergence(*law, config, 400, &stop), Cancelled);
  const std::atomic<bool> go{false};
  EXPECT_TRUE(predict_convergence(*law, config, 400, &go).available);

  IdentificationData data;
  data.sample_time_s = 0.005;
  data.pressure_difference_bar = Eigen::VectorXd(400);
  for (int k = 0; k < 400; ++k) {
    const double t = k * data.sample_time_s;
    data.pressure_difference_bar(k) = 0.2 * std::sin(2.0 * M_PI * t) + 0.1 * std::sin(2.0 * M_PI * 3.1 * t);
  }
  data.angle_rad = Eigen::VectorXd::Zero(400);
  data.angle_rad = simulate_arm_angle(config.model, data);
  EXPECT_THROW(fit_arm_model(data, config.model, &stop), Cancelled);
  EXPECT_NO_THROW(fit_arm_model(data, config.model, &go));
}

}  // namespace
}  // namespace bellows
