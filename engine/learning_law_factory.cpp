#include "engine/learning_law_factory.hpp"

#include "engine/errors.hpp"
#include "engine/noilc_dense.hpp"

namespace bellows {

std::vector<std::string> learning_law_names() { return {"noilc-dense"}; }

std::unique_ptr<LearningLaw> make_learning_law(const Configuration& config, const DiscreteArmModel& model, int samples) {
  const std::string& law = config.ilc.law;
  if (law == "noilc-dense") return std::make_unique<NormOptimalDense>(model, config.ilc, samples);
  std::string known;
  for (const std::string& name : learning_law_names()) known += (known.empty() ? "" : ", ") + name;
  throw InputError("[ilc] law = '" + law + "': unknown learning law (known: " + known + ")");
}

}  // namespace bellows
