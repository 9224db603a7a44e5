#include "app/identify_session.hpp"

#include <cstdio>

#include "engine/config/configuration_cost.hpp"
#include "engine/base/errors.hpp"
#include "engine/operator/learning_session.hpp"
#include "sessions/session_store.hpp"

namespace bellows {
namespace {

constexpr const char* kPurpose = "bellows identify";

std::string model_text(const ModelParameters& m) {
  char text[160];
  std::snprintf(text, sizeof text, "kappa %.6g rad/bar, omega0 %.6g 1/s, damping %.6g", m.kappa_rad_per_bar,
                m.omega0_rad_per_s, m.damping);
  return text;
}

}  // namespace

void IdentifySession::begin(const Configuration& config, const std::string& device,
                            const nlohmann::ordered_json& device_info, const Trajectory& excitation,
                            const std::string& validation_signal) {
  if (no_save_ || writer_) return;
  try {
    check_trial_cost(config, excitation.learning_samples());  // what loading the session would check
  } catch (const InputError& error) {
    not_recorded_ = std::string("the identification is not recorded in a session: ") + error.what();
    return;
  }
  SessionManifest header;
  header.device = device;
  header.device_info = device_info;
  header.configuration = config;
  char line[400];
  if (excitation.joints() > 1) {  // app/identify_chain: a trial per joint and signal
    std::snprintf(line, sizeof line,
                  "%s: for each of %d joints an identification trial (%s, +-%g deg, %g s) with the others held, then a "
                  "held-out %s trial each; fitting each joint's kappa, omega0 and damping and the coupled model of %s",
                  kPurpose, excitation.joints(), config.identify.signal.c_str(), config.identify.amplitude_deg,
                  config.identify.duration_s, validation_signal.c_str(), config.arm.name().c_str());
  } else {
    std::snprintf(
        line, sizeof line,
        "%s: an identification trial (%s, +-%g deg, %g s), then a held-out %s trial; fitting kappa, omega0 and "
        "damping from %s",
        kPurpose, excitation.name.c_str(), config.identify.amplitude_deg, config.identify.duration_s,
        validation_signal.c_str(), model_text(config.model).c_str());
  }
  header.events.push_back({utc_now(), 0, "start", line});
  const std::filesystem::path data_dir = data_dir_.empty() ? default_data_dir() : std::filesystem::path(data_dir_);
  writer_.emplace(SessionWriter::create(data_dir, name_, std::move(header), excitation, kPurpose));
}

void IdentifySession::save_estimation_trial(const Configuration& config, const std::string& signal,
                                            const TrialRecord& record) {
  if (!writer_) return;
  const Eigen::MatrixXd no_correction = Eigen::MatrixXd::Zero(record.learning_samples, record.joint_count());  // N x J
  const IterationSummary summary =
      summarize_trial(0, record, no_correction, config.controller.gas.ambient_bar, config.controller.p_max_bar);
  writer_->save_iteration(record, summary, no_correction, ResumeState{});
  char line[200];
  std::snprintf(line, sizeof line,
                "identification trial (%s): %d samples, tracking RMS %.3f deg; iteration 0 holds it%s", signal.c_str(),
                record.learning_samples, summary.rms_deg,
                record.joint_count() > 1 ? " (joint 1 excited; the other joints' trials are in the events)" : "");
  writer_->record_event("identify-trial", line);
}

void IdentifySession::note_validation_trial(const std::string& signal, const IdentificationData& data) {
  char line[200];
  std::snprintf(
      line, sizeof line,
      "held-out trial (%s): %lld samples every %g s (kept for the fit's validation, not saved as an iteration)",
      signal.c_str(), static_cast<long long>(data.angle_rad.size()), data.sample_time_s);
  record("identify-trial", line);
}

nlohmann::json model_json(const ModelParameters& m) {
  return {{"kappa", m.kappa_rad_per_bar}, {"omega0", m.omega0_rad_per_s}, {"damping", m.damping}};
}

void IdentifySession::note_fit(const ModelParameters& model, const ModelParameters& configured, double fit_percent,
                               double validation_fit_percent, double rms_residual_deg, int iterations, bool converged) {
  char line[400];
  std::snprintf(line, sizeof line,
                "%s: fit %.1f %%, %.1f %% on the held-out trial, rms residual %.3f deg, %d iterations%s (was %s)",
                model_text(model).c_str(), fit_percent, validation_fit_percent, rms_residual_deg, iterations,
                converged ? "" : ", not converged", model_text(configured).c_str());
  record("identify-fit", line);
}

void IdentifySession::record(const std::string& kind, const std::string& message) noexcept {
  if (!writer_) return;
  try {
    writer_->record_event(kind, message);
  } catch (const std::exception&) {
    // The session could not take it: what the caller reports goes on regardless.
  }
}

}  // namespace bellows
