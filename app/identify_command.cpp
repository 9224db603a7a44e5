#include "app/identify_command.hpp"

#include <cstdio>
#include <filesystem>
#include <optional>
#include <ostream>
#include <tuple>
#include <utility>
#include <vector>

#include <nlohmann/json.hpp>
#include <toml++/toml.h>

#include "app/config_file.hpp"
#include "app/device_factory.hpp"
#include "app/identify_chain.hpp"
#include "app/identify_session.hpp"
#include "app/rig_profile_file.hpp"
#include "app/rig_profile_write.hpp"
#include "app/toml_key_edit.hpp"
#include "app/signals.hpp"
#include "devices/simulated_arm.hpp"
#include "engine/rt/engine_core.hpp"
#include "engine/base/errors.hpp"
#include "engine/operator/identification.hpp"
#include "engine/operator/identification_trial.hpp"
#include "engine/base/printable_text.hpp"
#include "engine/rt/realtime_loop.hpp"
#include "sessions/atomic_file.hpp"
#include "sessions/file_access.hpp"

namespace bellows {
namespace {

struct TrialFit {
  std::string signal;
  IdentificationData data;
};

// One trial on `signal`'s excitation; the identification trial (the first) goes into the session.
// The engine holds `excitation` after the trial until another trajectory is selected: it must
// outlive the engine (on a rig the loop ticks on between the trials and reads it).
TrialFit record_trial(EngineDriver& driver, const Configuration& config, const Trajectory& excitation,
                      const std::string& signal, IdentifySession* session) {
  TrialRecord record;
  run_identification_trial(driver, excitation, config.timing, config.identify.max_abs_angle_deg, record,
                           &stop_requested());
  TrialFit fit{signal, identification_data(record, config.controller, config.timing.tick_s)};
  if (session != nullptr) session->save_estimation_trial(config, signal, record);
  return fit;
}

// The simulated arm: a fresh arm per trial on simulated time (the seed decides its noise).
TrialFit record_simulated_trial(const Configuration& config, const std::string& signal, std::uint64_t seed,
                                IdentifySession* session) {
  const Trajectory excitation = identification_trajectory(signal, config.identify, config.timing.sample_s());
  SimulatedArm arm(config.plant, seed);
  EngineCore core(arm, config.controller, config.timing, config.safety);
  SimulatedClock clock(core, arm);
  TrialFit fit = record_trial(clock, config, excitation, signal, session);
  arm.vent();
  return fit;
}

// A rig (lcm, t7): both trials on the one device, on the real-time loop; vented however it ends.
// The session begins once the rig serves.
std::pair<TrialFit, TrialFit> record_rig_trials(const Configuration& config, const DeviceParameters& device,
                                                const IdentifyOptions& options, const std::string& estimation_signal,
                                                const std::string& validation_signal, IdentifySession& session,
                                                std::ostream& progress) {
  // Declared before the engine, so that both outlive the loop that holds them.
  const Trajectory estimation = identification_trajectory(estimation_signal, config.identify, config.timing.sample_s());
  const Trajectory validation = identification_trajectory(validation_signal, config.identify, config.timing.sample_s());
  const std::unique_ptr<OpenedDevice> rig = open_device(device, config, options.seed, options.rt, 0,
                                                        std::filesystem::path(options.config_path).parent_path());
  EngineCore core(rig->device(), config.controller, config.timing, config.safety);
  RealtimeLoop loop(core, rig->device(), 1.0);
  loop.start(options.rt);
  struct StopLoop {  // vents on every way out
    RealtimeLoop& loop;
    OpenedDevice& rig;
    ~StopLoop() {
      loop.stop();
      rig.stop();
    }
  } stop_loop{loop, *rig};
  require_served(*rig, config.lcm.connect_timeout_s, stop_requested());
  session.begin(config, device.kind, rig->session_info(), estimation, validation_signal);
  if (!session.path().empty()) progress << "session " << session.path() << std::endl;
  if (!session.not_recorded().empty()) progress << "bellows: " << session.not_recorded() << std::endl;
  progress << "identification trial (" << estimation_signal << ") on " << device.kind << " " << rig->where()
           << std::endl;
  TrialFit estimation_fit = record_trial(loop, config, estimation, estimation_signal, &session);
  progress << "validation trial (" << validation_signal << ")" << std::endl;
  TrialFit validation_fit = record_trial(loop, config, validation, validation_signal, nullptr);
  return {std::move(estimation_fit), std::move(validation_fit)};
}

}  // namespace

std::string model_held_in(const std::string& toml_text, bool rig_profile, bool several_joints) {
  const toml::table table = toml::parse(toml_text);
  std::vector<std::string> held;
  if (several_joints) {
    for (const auto& [key, node] : table) {
      if (key.str().rfind("identified_joint", 0) == 0 && node.is_table())
        held.push_back("[" + std::string(key.str()) + "]");
    }
  } else if (const toml::table* model = table["model"].as_table()) {
    // The keys identify writes: a profile's (units in the names) or a configuration's.
    const std::vector<std::string> keys =
        rig_profile ? std::vector<std::string>{"kappa_rad_per_bar", "omega0_rad_per_s", "damping"}
                    : std::vector<std::string>{"kappa", "omega0", "damping"};
    for (const std::string& key : keys) {
      if (const toml::node* value = model->get(key)) {
        const std::optional<double> number = value->value<double>();
        held.push_back((held.empty() ? "[model] " : "") + key + " = " +
                       (number ? toml_number(*number) : std::string("...")));
      }
    }
  }
  std::string out;
  for (const std::string& part : held) out += (out.empty() ? "" : ", ") + part;
  return out;
}

void check_write_model_target(const IdentifyOptions& options, const std::string& toml_text, bool exists,
                              bool rig_profile, bool several_joints) {
  if (!exists || options.force) return;
  if (const std::string held = model_held_in(toml_text, rig_profile, several_joints); !held.empty()) {
    throw InputError("--write-model " + printable(options.write_model_path, kPrintableField) +
                     " holds a model already (" + held + "): --force replaces it (the rest of the file is kept)");
  }
}

std::string with_model_section(const std::string& toml_text, const std::string& source_name,
                               const ModelParameters& model) {
  std::string text = with_table_values(toml_text, "model",  // not const: returned by move
                                       {{"kappa", toml_number(model.kappa_rad_per_bar)},
                                        {"omega0", toml_number(model.omega0_rad_per_s)},
                                        {"damping", toml_number(model.damping)}},
                                       "fitted by bellows identify");
  Configuration check;
  apply_config_toml(text, source_name, check);  // never write a file the loader would reject
  if (check.model.kappa_rad_per_bar != std::stod(toml_number(model.kappa_rad_per_bar))) {
    throw InputError("config " + source_name + ": [model] could not be updated in place (dotted or inline keys?)");
  }
  return text;
}

int identify_command(const IdentifyOptions& options, std::ostream& out, std::ostream& progress) {
  Configuration config = options.config_path.empty() ? Configuration{} : load_config_file(options.config_path);
  std::string plant_source = options.config_path.empty() ? "the default plant" : "the plant of " + options.config_path;
  // --write-model FILE: a rig profile (it has [valves]) gets the model identified on its rig; a
  // configuration gets its [model]. Either must be valid before any trial runs.
  std::string existing_text;
  bool into_profile = false;
  if (!options.write_model_path.empty() && std::filesystem::exists(options.write_model_path)) {
    // A directory, FIFO or device is refused, and the read is bounded, as for --config.
    existing_text = read_regular_file(options.write_model_path, kMaxConfigFileBytes, "config");
    into_profile = is_rig_profile_file(options.write_model_path);
    if (into_profile) {
      parse_rig_profile(existing_text, options.write_model_path);
    } else {
      Configuration written;
      apply_config_toml(existing_text, options.write_model_path, written);
      // The file whose model is fitted describes the arm: without --config, its [plant] is the one fitted.
      if (options.config_path.empty() && (toml::parse(existing_text).contains("plant") || written.arm.has_chain())) {
        config = written;
        plant_source = "the plant of " + options.write_model_path;
      }
    }
  }
  const bool write_model_exists =
      !options.write_model_path.empty() && std::filesystem::exists(options.write_model_path);
  if (!options.signal.empty()) config.identify.signal = options.signal;
  if (config.arm.has_chain()) {  // every joint, and the coupled model (app/identify_chain)
    if (into_profile) {
      throw InputError("--write-model " + options.write_model_path +
                       ": a rig profile holds one joint's [model]; the coupled model of " + config.arm.name() +
                       " goes into its configuration");
    }
    check_write_model_target(options, existing_text, write_model_exists, false, true);
    return identify_chain_command(options, config, existing_text, out, progress);
  }
  check_write_model_target(options, existing_text, write_model_exists, into_profile, false);
  const std::string estimation_signal = config.identify.signal;
  const std::string held_out_signal = validation_signal(estimation_signal);

  const DeviceParameters device = resolve_device(options.device, config.device);
  IdentifySession session(options.no_save, options.data_dir, options.session_name);
  TrialFit estimation, validation;
  ArmModelFit fit;
  double validation_fit = 0.0, nominal_validation_fit = 0.0;
  try {
    if (device.kind == "sim") {
      session.begin(config, device.kind, {{"seed", options.seed}},
                    identification_trajectory(estimation_signal, config.identify, config.timing.sample_s()),
                    held_out_signal);
      if (!session.path().empty()) progress << "session " << session.path() << std::endl;
      if (!session.not_recorded().empty()) progress << "bellows: " << session.not_recorded() << std::endl;
      progress << "fitting " << plant_source << std::endl;
      progress << "identification trial (" << estimation_signal << ", +-" << config.identify.amplitude_deg << " deg, "
               << config.identify.duration_s << " s)" << std::endl;
      estimation = record_simulated_trial(config, estimation_signal, options.seed, &session);
      progress << "validation trial (" << held_out_signal << ")" << std::endl;
      validation = record_simulated_trial(config, held_out_signal, options.seed + 1, nullptr);
    } else {
      std::tie(estimation, validation) =
          record_rig_trials(config, device, options, estimation_signal, held_out_signal, session, progress);
    }
    session.note_validation_trial(held_out_signal, validation.data);
    fit = fit_arm_model(estimation.data, config.model, &stop_requested());
    validation_fit = normalized_fit_percent(validation.data.angle_rad, simulate_arm_angle(fit.model, validation.data));
    nominal_validation_fit =
        normalized_fit_percent(validation.data.angle_rad, simulate_arm_angle(config.model, validation.data));
    session.note_fit(fit.model, config.model, fit.fit_percent, validation_fit, fit.rms_residual_deg, fit.iterations,
                     fit.converged);

    if (!options.write_model_path.empty()) {
      if (into_profile) {
        write_rig_profile_model(options.write_model_path, fit.model);
        progress << "wrote [model] to the rig profile " << options.write_model_path << std::endl;
        session.record("model-written",
                       "[model] kappa_rad_per_bar, omega0_rad_per_s, damping written into the rig profile " +
                           options.write_model_path);
      } else {
        // Created (a file that appeared meanwhile is refused), or the file read above, edited.
        write_file_atomic(options.write_model_path,
                          with_model_section(existing_text, options.write_model_path, fit.model), DirectorySync::kNow,
                          write_model_exists ? Replace::kAllowed : Replace::kRefused);
        progress << "wrote [model] to " << options.write_model_path << std::endl;
        session.record("model-written",
                       "[model] kappa, omega0, damping written into the configuration " + options.write_model_path);
      }
    }
  } catch (const std::exception& error) {
    session.record("fault", error.what());  // the trials so far stay in the session
    throw;
  }
  session.record("finish", options.write_model_path.empty()
                               ? "identified; the model was written nowhere (--write-model FILE)"
                               : "identified; the model is in " + options.write_model_path);
  if (options.json) {
    const nlohmann::json report = {
        {"device", device.kind},
        {"signal", estimation_signal},
        {"validation_signal", held_out_signal},
        {"samples", estimation.data.angle_rad.size()},
        {"sample_time_s", estimation.data.sample_time_s},
        {"model", model_json(fit.model)},
        {"initial_model", model_json(fit.initial)},
        {"configured_model", model_json(config.model)},
        {"fit_percent", fit.fit_percent},
        {"validation_fit_percent", validation_fit},
        {"configured_model_validation_fit_percent", nominal_validation_fit},
        {"rms_residual_deg", fit.rms_residual_deg},
        {"iterations", fit.iterations},
        {"converged", fit.converged},
        {"written_to",
         options.write_model_path.empty() ? nlohmann::json(nullptr) : nlohmann::json(options.write_model_path)},
        {"written_as", options.write_model_path.empty() ? nlohmann::json(nullptr)
                                                        : nlohmann::json(into_profile ? "rig_profile" : "config")},
        {"session", session.path().empty() ? nlohmann::json(nullptr) : nlohmann::json(session.path())}};
    out << report.dump() << std::endl;
  } else {
    char text[512];
    std::snprintf(text, sizeof text,
                  "kappa %.4f rad/bar  omega0 %.4f 1/s  damping %.4f\n"
                  "fit %.1f %% on %s, %.1f %% on held-out %s (configured model: %.1f %%), rms residual %.3f deg, "
                  "%d iterations%s\n",
                  fit.model.kappa_rad_per_bar, fit.model.omega0_rad_per_s, fit.model.damping, fit.fit_percent,
                  estimation_signal.c_str(), validation_fit, held_out_signal.c_str(), nominal_validation_fit,
                  fit.rms_residual_deg, fit.iterations, fit.converged ? "" : " (not converged)");
    out << text;
  }
  return 0;
}

}  // namespace bellows
