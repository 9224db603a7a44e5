#include "app/learning_report.hpp"

namespace bellows {
namespace {

nlohmann::json estimate_json(const ContractionEstimate& e) {
  return {{"kappa_scale", e.kappa_scale},
          {"omega0_scale", e.omega0_scale},
          {"contraction", e.contraction},
          {"worst_frequency_hz", e.worst_frequency_hz}};
}

nlohmann::json prediction_fields(const ConvergencePrediction& p, const char* method) {
  if (!p.available) return {{"available", false}};
  nlohmann::json grid = nlohmann::json::array();
  for (const ContractionEstimate& e : p.grid) grid.push_back(estimate_json(e));
  return {{"available", true},
          {"method", method},
          {"band_hz", {p.band_low_hz, p.band_high_hz}},
          {"model_error", p.model_error},
          {"nominal", estimate_json(p.nominal)},
          {"worst", estimate_json(p.worst)},
          {"diverging_points", p.diverging_points},
          {"grid", grid},
          {"warning", p.warning.empty() ? nlohmann::json(nullptr) : nlohmann::json(p.warning)}};
}

constexpr const char* kFrequencyMethod =
    "frequency response of the law against the PID closed loop, long-trial approximation";
constexpr const char* kLiftedMethod =
    "largest singular value of the lifted map from one trial's correction to the next (every joint and sample) on "
    "the arm's coupled PID closed loop, the chain linearized stretched out";

nlohmann::json learning_diagnostics_json(const LearningDiagnostics& d) {
  return {{"contraction", d.contraction ? nlohmann::json(*d.contraction) : nlohmann::json(nullptr)},
          {"correction_change_bar", d.correction_change_bar},
          {"saturated_samples", d.saturated_samples},
          {"clamped_excess_bar", d.clamped_excess_bar},
          {"windup_samples", d.windup_samples}};
}

}  // namespace

nlohmann::json prediction_json(const ConvergencePrediction& p) { return prediction_fields(p, kFrequencyMethod); }

nlohmann::json joint_prediction_json(const JointConvergencePrediction& p) {
  nlohmann::json out = prediction_fields(p.arm, kLiftedMethod);
  out["joints_learned"] = p.learned_together ? "together" : "each on its own";
  if (!p.arm.available) {
    out["reason"] = p.unavailable_reason;
    return out;
  }
  nlohmann::json joints = nlohmann::json::array();
  for (std::size_t j = 0; j < p.joints.size(); ++j) {
    const JointConvergence& joint = p.joints[j];
    nlohmann::json entry = {{"joint", j + 1},
                            {"contraction", joint.contraction},
                            {"slowest_direction_share", joint.slowest_direction_share}};
    if (!p.learned_together) entry["own_model"] = prediction_fields(joint.own, kFrequencyMethod);
    joints.push_back(entry);
  }
  out["joints"] = joints;
  out["lanczos_steps"] = p.iterations;
  return out;
}

nlohmann::json diagnostics_json(const IterationDiagnostics& d) {
  nlohmann::json out = learning_diagnostics_json(d);
  if (d.joints.empty()) return out;  // one joint: the arm's figures are its own
  nlohmann::json joints = nlohmann::json::array();
  for (const LearningDiagnostics& joint : d.joints) joints.push_back(learning_diagnostics_json(joint));
  out["joint_diagnostics"] = joints;
  return out;
}

nlohmann::json windup_json(const WindupSummary& w) {
  nlohmann::json out = {
      {"detected", w.detected},
      {"iterations_with_windup", w.iterations_with_windup},
      {"first_iteration", w.first_iteration ? nlohmann::json(*w.first_iteration) : nlohmann::json(nullptr)},
      {"max_clamped_excess_bar", w.max_clamped_excess_bar},
      {"last_clamped_excess_bar", w.last_clamped_excess_bar}};
  if (w.joints.empty()) return out;
  nlohmann::json joints = nlohmann::json::array();
  for (const WindupSummary& joint : w.joints) joints.push_back(windup_json(joint));
  out["joints"] = joints;
  return out;
}

}  // namespace bellows
