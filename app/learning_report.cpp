#include "app/learning_report.hpp"

namespace bellows {
namespace {

nlohmann::json estimate_json(const ContractionEstimate& e) {
  return {{"kappa_scale", e.kappa_scale},
          {"omega0_scale", e.omega0_scale},
          {"contraction", e.contraction},
          {"worst_frequency_hz", e.worst_frequency_hz}};
}

}  // namespace

nlohmann::json prediction_json(const ConvergencePrediction& p) {
  if (!p.available) return {{"available", false}};
  nlohmann::json grid = nlohmann::json::array();
  for (const ContractionEstimate& e : p.grid) grid.push_back(estimate_json(e));
  return {{"available", true},
          {"method", "frequency response of the law against the PID closed loop, long-trial approximation"},
          {"band_hz", {p.band_low_hz, p.band_high_hz}},
          {"model_error", p.model_error},
          {"nominal", estimate_json(p.nominal)},
          {"worst", estimate_json(p.worst)},
          {"diverging_points", p.diverging_points},
          {"grid", grid},
          {"warning", p.warning.empty() ? nlohmann::json(nullptr) : nlohmann::json(p.warning)}};
}

nlohmann::json diagnostics_json(const IterationDiagnostics& d) {
  return {{"contraction", d.contraction ? nlohmann::json(*d.contraction) : nlohmann::json(nullptr)},
          {"correction_change_bar", d.correction_change_bar},
          {"saturated_samples", d.saturated_samples},
          {"clamped_excess_bar", d.clamped_excess_bar},
          {"windup_samples", d.windup_samples}};
}

nlohmann::json windup_json(const WindupSummary& w) {
  return {{"detected", w.detected},
          {"iterations_with_windup", w.iterations_with_windup},
          {"first_iteration", w.first_iteration ? nlohmann::json(*w.first_iteration) : nlohmann::json(nullptr)},
          {"max_clamped_excess_bar", w.max_clamped_excess_bar},
          {"last_clamped_excess_bar", w.last_clamped_excess_bar}};
}

}  // namespace bellows
