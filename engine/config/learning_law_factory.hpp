// Builds the learning law a configuration names (`[ilc] law`).
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "engine/model/arm_model.hpp"
#include "engine/config/configuration.hpp"
#include "engine/learning/learning_law.hpp"
#include "engine/operator/learning_session.hpp"

namespace bellows {

/// The law names `[ilc] law` accepts.
std::vector<std::string> learning_law_names();
/// One line on what a law does, for help texts and the console; throws InputError if unknown.
std::string learning_law_description(const std::string& name);

/// The `[ilc]` keys law `name` reads (its weights and gains), in the configuration table's order;
/// throws InputError if unknown.
std::vector<std::string> learning_law_weight_keys(const std::string& name);
/// The configuration's law and the values of its weight keys: what a correction learned now is
/// learned with (recorded with each saved iteration).
LearnedWith learned_with(const Configuration& config);

/// Throws InputError for an unknown name or weights the law cannot use.
std::unique_ptr<LearningLaw> make_learning_law(const Configuration& config, const DiscreteArmModel& model, int samples);

}  // namespace bellows
