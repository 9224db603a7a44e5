// JSON for what learning predicts and observes (engine/config/convergence, engine/learning/learning_monitor):
// shared by `bellows run --json` and anything else that reports a run.
#pragma once

#include <nlohmann/json.hpp>

#include "engine/config/convergence.hpp"
#include "engine/config/joint_convergence.hpp"
#include "engine/learning/learning_monitor.hpp"

namespace bellows {

nlohmann::json prediction_json(const ConvergencePrediction& prediction);
/// An arm of several joints: the arm's prediction (the fields of prediction_json, "method" the lifted
/// one), "joints_learned", and per joint "joints": [{joint, contraction, slowest_direction_share,
/// own_model (laws per joint: that joint's prediction_json)}].
nlohmann::json joint_prediction_json(const JointConvergencePrediction& prediction);
/// The per-iteration diagnostics, to merge into an iteration's object (several joints: each joint's
/// in "joint_diagnostics").
nlohmann::json diagnostics_json(const IterationDiagnostics& diagnostics);
/// Several joints: each joint's in "joints".
nlohmann::json windup_json(const WindupSummary& windup);

}  // namespace bellows
