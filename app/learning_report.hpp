// JSON for what learning predicts and observes (engine/config/convergence, engine/learning/learning_monitor):
// shared by `bellows run --json` and anything else that reports a run.
#pragma once

#include <nlohmann/json.hpp>

#include "engine/config/convergence.hpp"
#include "engine/learning/learning_monitor.hpp"

namespace bellows {

nlohmann::json prediction_json(const ConvergencePrediction& prediction);
/// The per-iteration diagnostics, to merge into an iteration's object.
nlohmann::json diagnostics_json(const IterationDiagnostics& diagnostics);
nlohmann::json windup_json(const WindupSummary& windup);

}  // namespace bellows
