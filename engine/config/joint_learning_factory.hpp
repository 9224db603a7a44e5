// Builds the learning of an arm of J joints from the configuration: `[ilc] law` and, for several
// joints, `[ilc] joint_model` and the `[arm]` chain (docs/learning-laws.md, "Several joints").
//  - one joint: today's single-joint law (make_learning_law) on `model`, unchanged;
//  - noilc, noilc-constrained: the J-joint norm-optimal update (engine/learning/noilc_mimo*) with the chain
//    linearized stretched out (`coupled`), each joint's own single-joint model (`independent`) or
//    the coupled model `bellows identify` fitted (`identified`, [identified_joint1..J]);
//  - the other laws: one single-joint law per joint, each on its joint's own model.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "engine/model/arm_chain_parameters.hpp"
#include "engine/config/configuration.hpp"
#include "engine/learning/joint_learning.hpp"
#include "engine/model/multi_joint_model.hpp"

namespace bellows {

/// Each joint of `chain` as a single-joint arm's [model] (its row of the spec's table: kappa, w0 with
/// the arm straight, delta; the other keys their defaults), the rest of the chain held still.
std::vector<ModelParameters> independent_joint_parameters(const ChainParameters& chain);

/// Each joint of `chain` as a single-joint arm (its row of the spec's table: kappa, w0 with the arm
/// straight, delta), the rest of the chain held still.
std::vector<DiscreteArmModel> independent_joint_models(const ChainParameters& chain, double sample_time_s);

/// The model the J-joint norm-optimal update uses: the chain linearized stretched out (coupled), the
/// block-diagonal model of independent_joint_models (independent), or the coupled model `bellows
/// identify` fitted (identified: `identified`'s first J rows, InputError when they hold none).
MultiJointModel joint_learning_model(const ChainParameters& chain, const std::string& joint_model, double sample_time_s,
                                     const IdentifiedArmParameters& identified = {});

/// True for the laws whose J-joint form learns every joint in one update (noilc, noilc-constrained,
/// noilc-learned); the others learn each joint on its own, with that joint's model.
bool learns_joints_together(const std::string& law);

/// The learning for `joints` joints of `samples` samples. `model` is the single-joint model (one
/// joint only). Throws InputError for a law, model or weights that cannot be used, or a joint count
/// other than the [arm]'s.
std::unique_ptr<JointLearning> make_joint_learning(const Configuration& config, const DiscreteArmModel& model,
                                                   int joints, int samples);

}  // namespace bellows
