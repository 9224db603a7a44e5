#include "engine/config/learning_law_factory.hpp"

#include <stdexcept>

#include "engine/config/configuration_cost.hpp"
#include "engine/base/errors.hpp"
#include "engine/learning/gradient_ilc.hpp"
#include "engine/learning/inverse_ilc.hpp"
#include "engine/learning/noilc_constrained.hpp"
#include "engine/learning/noilc_dense.hpp"
#include "engine/learning/noilc_learned.hpp"
#include "engine/learning/noilc_riccati.hpp"
#include "engine/learning/pd_ilc.hpp"

namespace bellows {

std::vector<std::string> learning_law_names() {
  return {"noilc", "noilc-dense", "noilc-constrained", "noilc-learned", "pd", "gradient", "inverse"};
}

std::string learning_law_description(const std::string& name) {
  if (name == "noilc") return "norm-optimal ILC, O(N) Riccati form (the paper's optimum; default)";
  if (name == "noilc-dense") return "norm-optimal ILC, the paper's dense closed form (O(N^2) memory)";
  if (name == "noilc-constrained") return "norm-optimal ILC that keeps the set points within the pressure limits";
  if (name == "noilc-learned") return "norm-optimal ILC on the closed loop's model, refined from the session's trials";
  if (name == "pd") return "PD-type ILC with a zero-phase Q-filter (the paper's comparison)";
  if (name == "gradient") return "steepest-descent ILC along P'e";
  if (name == "inverse") return "robust inverse-model ILC with a zero-phase Q-filter";
  throw InputError("unknown learning law '" + name + "'");
}

std::vector<std::string> learning_law_weight_keys(const std::string& name) {
  if (name == "noilc" || name == "noilc-dense") return {"m", "s", "w"};
  if (name == "noilc-constrained") {
    return {"m", "s", "w", "admm_rho", "admm_max_iterations", "admm_tolerance", "limit_margin_bar", "limit_recovery_s"};
  }
  if (name == "noilc-learned") {
    return {"m",
            "learned_s",
            "w",
            "learned_forgetting",
            "learned_ridge",
            "learned_guard",
            "learned_taps",
            "learned_joints_refit_plans",
            "learned_joints_zero_limited",
            "learned_joints_descent_slack",
            "limit_margin_bar",
            "limit_recovery_s"};
  }
  if (name == "pd") return {"pd_kp", "pd_kd_s", "pd_q_cutoff_hz"};
  if (name == "gradient") return {"gradient_step"};
  if (name == "inverse") return {"inverse_gain", "inverse_q_cutoff_hz"};
  throw InputError("unknown learning law '" + name + "'");
}

LearnedWith learned_with(const Configuration& config) {
  LearnedWith out{config.ilc.law, {}};
  Configuration copy = config;  // the bindings point into a Configuration they may change
  for (const std::string& key : learning_law_weight_keys(config.ilc.law)) {
    const ParameterBinding* binding = find_parameter("ilc", key);
    if (binding == nullptr) throw std::logic_error("learned_with: no [ilc] " + key + " in the configuration table");
    out.weights.emplace_back(key, binding->real ? *binding->real(copy) : static_cast<double>(*binding->integer(copy)));
  }
  return out;
}

std::unique_ptr<LearningLaw> make_learning_law(const Configuration& config, const DiscreteArmModel& model,
                                               int samples) {
  const std::string& law = config.ilc.law;
  check_trial_cost(config, samples);  // before any matrix of the law is allocated
  try {
    if (law == "noilc") return std::make_unique<NormOptimalRiccati>(model, config.ilc, samples);
    if (law == "noilc-dense") return std::make_unique<NormOptimalDense>(model, config.ilc, samples);
    if (law == "noilc-constrained") return std::make_unique<NormOptimalConstrained>(model, config.ilc, samples);
    if (law == "noilc-learned") {
      return std::make_unique<NoilcLearnedLaw>(
          closed_loop_prior(model.A, model.B, model.sample_time_s, config.model.volume_gain_per_rad, config.controller),
          learned_noilc_settings(config.ilc), samples);
    }
    if (law == "pd") return std::make_unique<PdIlc>(model, config.ilc, samples);
    if (law == "gradient") return std::make_unique<GradientIlc>(model, config.ilc, samples);
    if (law == "inverse") return std::make_unique<InverseIlc>(model, config.ilc, samples);
  } catch (const InputError& error) {
    throw InputError("[ilc] law = '" + law + "': " + error.what());
  }
  std::string known;
  for (const std::string& name : learning_law_names()) known += (known.empty() ? "" : ", ") + name;
  throw InputError("[ilc] law = '" + law + "': unknown learning law (known: " + known + ")");
}

}  // namespace bellows
