// The session `bellows identify` is recorded in (docs/rig-bring-up.md, "Identify the model"), where
// runs save theirs: its manifest has the device (with its address and rig profile) and the
// configuration, its trajectory is the identification excitation and its iteration 0 the
// identification trial (angle, pressures and valves at the ILC rate and the tick rate, as any
// trial's); its events are the trials, the fit, what was written where, and the outcome.
#pragma once

#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>

#include <nlohmann/json.hpp>

#include "engine/config/configuration.hpp"
#include "engine/operator/identification.hpp"
#include "engine/trial/trajectory.hpp"
#include "engine/trial/trial_record.hpp"
#include "sessions/session_writer.hpp"

namespace bellows {

/// A model's three parameters as the JSON reports of `identify` (one joint and a chain) write them.
nlohmann::json model_json(const ModelParameters& m);

class IdentifySession {
 public:
  /// Nothing is recorded with `no_save`; otherwise the session is created by begin().
  IdentifySession(bool no_save, std::string data_dir, std::string name)
      : no_save_(no_save), data_dir_(std::move(data_dir)), name_(std::move(name)) {}

  /// Creates the session (once the device serves): `excitation` becomes its trajectory.
  /// Throws InputError when it cannot be created. An excitation longer than a session of this
  /// configuration could load again (its learning law's limits) is not recorded: not_recorded() says why.
  void begin(const Configuration& config, const std::string& device, const nlohmann::ordered_json& device_info,
             const Trajectory& excitation, const std::string& validation_signal);
  /// The identification trial (the first, on `excitation`): its record becomes iteration 0.
  void save_estimation_trial(const Configuration& config, const std::string& signal, const TrialRecord& record);
  /// The held-out trial: an event (its record is on another excitation, not the session's trajectory).
  void note_validation_trial(const std::string& signal, const IdentificationData& data);
  /// The fit (`fit_percent` on the identification trial, `validation_fit_percent` on the held-out one).
  void note_fit(const ModelParameters& model, const ModelParameters& configured, double fit_percent,
                double validation_fit_percent, double rms_residual_deg, int iterations, bool converged);
  /// Never throws (the failure itself is what the caller reports).
  void record(const std::string& kind, const std::string& message) noexcept;

  /// The session directory; empty with --no-save or before begin().
  std::string path() const { return writer_ ? writer_->directory().string() : std::string(); }
  const std::string& not_recorded() const { return not_recorded_; }

 private:
  bool no_save_;
  std::string data_dir_;
  std::string name_;
  std::optional<SessionWriter> writer_;
  std::string not_recorded_;
};

}  // namespace bellows
