// Builds the learning law a configuration names (`[ilc] law`).
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "engine/model/arm_model.hpp"
#include "engine/config/configuration.hpp"
#include "engine/learning/learning_law.hpp"

namespace bellows {

/// The law names `[ilc] law` accepts.
std::vector<std::string> learning_law_names();
/// One line on what a law does, for help texts and the console; throws InputError if unknown.
std::string learning_law_description(const std::string& name);

/// Throws InputError for an unknown name or weights the law cannot use.
std::unique_ptr<LearningLaw> make_learning_law(const Configuration& config, const DiscreteArmModel& model, int samples);

}  // namespace bellows
