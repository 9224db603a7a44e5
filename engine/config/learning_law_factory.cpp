#include "engine/config/learning_law_factory.hpp"

#include "engine/config/configuration_cost.hpp"
#include "engine/base/errors.hpp"
#include "engine/learning/gradient_ilc.hpp"
#include "engine/learning/inverse_ilc.hpp"
#include "engine/learning/noilc_constrained.hpp"
#include "engine/learning/noilc_dense.hpp"
#include "engine/learning/noilc_riccati.hpp"
#include "engine/learning/pd_ilc.hpp"

namespace bellows {

std::vector<std::string> learning_law_names() {
  return {"noilc", "noilc-dense", "noilc-constrained", "pd", "gradient", "inverse"};
}

std::string learning_law_description(const std::string& name) {
  if (name == "noilc") return "norm-optimal ILC, O(N) Riccati form (the paper's optimum; default)";
  if (name == "noilc-dense") return "norm-optimal ILC, the paper's dense closed form (O(N^2) memory)";
  if (name == "noilc-constrained") return "norm-optimal ILC that keeps the set points within the pressure limits";
  if (name == "pd") return "PD-type ILC with a zero-phase Q-filter (the paper's comparison)";
  if (name == "gradient") return "steepest-descent ILC along P'e";
  if (name == "inverse") return "robust inverse-model ILC with a zero-phase Q-filter";
  throw InputError("unknown learning law '" + name + "'");
}

std::unique_ptr<LearningLaw> make_learning_law(const Configuration& config, const DiscreteArmModel& model, int samples) {
  const std::string& law = config.ilc.law;
  check_trial_cost(config, samples);  // before any matrix of the law is allocated
  try {
    if (law == "noilc") return std::make_unique<NormOptimalRiccati>(model, config.ilc, samples);
    if (law == "noilc-dense") return std::make_unique<NormOptimalDense>(model, config.ilc, samples);
    if (law == "noilc-constrained") return std::make_unique<NormOptimalConstrained>(model, config.ilc, samples);
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
