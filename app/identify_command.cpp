#include "app/identify_command.hpp"

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <ostream>
#include <sstream>
#include <tuple>
#include <utility>
#include <vector>

#include <nlohmann/json.hpp>
#include <toml++/toml.h>

#include "app/config_file.hpp"
#include "app/device_factory.hpp"
#include "app/signals.hpp"
#include "devices/simulated_arm.hpp"
#include "engine/engine_core.hpp"
#include "engine/errors.hpp"
#include "engine/identification.hpp"
#include "engine/identification_trial.hpp"
#include "engine/printable_text.hpp"
#include "engine/realtime_loop.hpp"
#include "sessions/file_access.hpp"

namespace bellows {
namespace {

std::string format_value(double value) {
  char text[64];
  std::snprintf(text, sizeof text, "%.6g", value);
  return text;
}

struct TrialFit {
  std::string signal;
  IdentificationData data;
};

TrialFit record_trial(EngineDriver& driver, const Configuration& config, const std::string& signal) {
  const Trajectory excitation = identification_trajectory(signal, config.identify, config.timing.sample_s());
  TrialRecord record;
  run_identification_trial(driver, excitation, config.timing, config.identify.max_abs_angle_deg, record, &stop_requested());
  return {signal, identification_data(record, config.controller, config.timing.tick_s)};
}

// The simulated arm: a fresh arm per trial on simulated time (the seed decides its noise).
TrialFit record_simulated_trial(const Configuration& config, const std::string& signal, std::uint64_t seed) {
  SimulatedArm arm(config.plant, seed);
  EngineCore core(arm, config.controller, config.timing, config.safety);
  SimulatedClock clock(core, arm);
  TrialFit fit = record_trial(clock, config, signal);
  arm.vent();
  return fit;
}

// A rig (lcm, t7): both trials on the one device, on the real-time loop; vented however it ends.
std::pair<TrialFit, TrialFit> record_rig_trials(const Configuration& config, const DeviceParameters& device,
                                                const IdentifyOptions& options, const std::string& estimation_signal,
                                                const std::string& validation_signal, std::ostream& progress) {
  const std::unique_ptr<OpenedDevice> rig = open_device(device, config, options.seed, options.rt, 0, std::filesystem::path(options.config_path).parent_path());
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
  if (const std::string why = rig->wait_until_served(config.lcm.connect_timeout_s, stop_requested()); !why.empty()) {
    throw EnvironmentError(why);
  }
  progress << "identification trial (" << estimation_signal << ") on " << device.kind << " " << rig->where() << std::endl;
  TrialFit estimation = record_trial(loop, config, estimation_signal);
  progress << "validation trial (" << validation_signal << ")" << std::endl;
  TrialFit validation = record_trial(loop, config, validation_signal);
  return {std::move(estimation), std::move(validation)};
}

nlohmann::json model_json(const ModelParameters& m) {
  return {{"kappa", m.kappa_rad_per_bar}, {"omega0", m.omega0_rad_per_s}, {"damping", m.damping}};
}

void write_text_atomically(const std::string& path, const std::string& text) {
  const std::string temporary = path + ".tmp";
  {
    std::ofstream out(temporary, std::ios::trunc);
    if (!out) throw EnvironmentError("cannot write " + temporary);
    out << text;
    if (!out.flush()) throw EnvironmentError("cannot write " + temporary);
  }
  std::error_code error;
  std::filesystem::rename(temporary, path, error);
  if (error) throw EnvironmentError("cannot replace " + path + ": " + error.message());
}

}  // namespace

std::string with_model_section(const std::string& toml_text, const std::string& source_name, const ModelParameters& model) {
  const std::vector<std::pair<std::string, double>> values = {
      {"kappa", model.kappa_rad_per_bar}, {"omega0", model.omega0_rad_per_s}, {"damping", model.damping}};
  std::vector<std::string> lines;
  std::istringstream in(toml_text);
  for (std::string line; std::getline(in, line);) lines.push_back(line);

  std::vector<bool> written(values.size(), false);
  bool in_model = false;
  long header = -1, section_end = -1;
  for (std::size_t i = 0; i < lines.size(); ++i) {
    const std::string t(trim(lines[i]));
    if (!t.empty() && t.front() == '[') {
      if (in_model) section_end = static_cast<long>(i);
      in_model = t.rfind("[model]", 0) == 0 && (t.size() == 7 || trim(t.substr(7)).rfind('#', 0) == 0);
      if (in_model) header = static_cast<long>(i);
      continue;
    }
    if (!in_model) continue;
    const auto equals = t.find('=');
    if (equals == std::string::npos) continue;
    const std::string key(trim(t.substr(0, equals)));
    for (std::size_t v = 0; v < values.size(); ++v) {
      if (key == values[v].first) {
        lines[i] = values[v].first + " = " + format_value(values[v].second) + "  # fitted by bellows identify";
        written[v] = true;
      }
    }
  }
  if (in_model && section_end < 0) section_end = static_cast<long>(lines.size());
  std::vector<std::string> missing;
  for (std::size_t v = 0; v < values.size(); ++v) {
    if (!written[v]) missing.push_back(values[v].first + " = " + format_value(values[v].second) + "  # fitted by bellows identify");
  }
  if (header < 0) {
    if (!lines.empty() && !trim(lines.back()).empty()) lines.emplace_back();
    lines.emplace_back("[model]");
    lines.insert(lines.end(), missing.begin(), missing.end());
  } else {
    lines.insert(lines.begin() + header + 1, missing.begin(), missing.end());
  }
  std::string text;
  for (const std::string& line : lines) text += line + "\n";
  Configuration check;
  apply_config_toml(text, source_name, check);  // never write a file the loader would reject
  if (check.model.kappa_rad_per_bar != std::stod(format_value(model.kappa_rad_per_bar))) {
    throw InputError("config " + source_name + ": [model] could not be updated in place (dotted or inline keys?)");
  }
  return text;
}

int identify_command(const IdentifyOptions& options, std::ostream& out, std::ostream& progress) {
  Configuration config = options.config_path.empty() ? Configuration{} : load_config_file(options.config_path);
  std::string plant_source = options.config_path.empty() ? "the default plant" : "the plant of " + options.config_path;
  std::string existing_text;
  if (!options.write_model_path.empty() && std::filesystem::exists(options.write_model_path)) {
    // A directory, FIFO or device is refused, and the read is bounded, as for --config.
    existing_text = read_regular_file(options.write_model_path, kMaxConfigFileBytes, "config");
    Configuration written;
    apply_config_toml(existing_text, options.write_model_path, written);  // fail before any trial runs
    // The file whose model is fitted describes the arm: without --config, its [plant] is the one fitted.
    if (options.config_path.empty() && toml::parse(existing_text).contains("plant")) {
      config = written;
      plant_source = "the plant of " + options.write_model_path;
    }
  }
  if (!options.signal.empty()) config.identify.signal = options.signal;
  const std::string estimation_signal = config.identify.signal;
  const std::string held_out_signal = validation_signal(estimation_signal);

  const DeviceParameters device = resolve_device(options.device, config.device);
  TrialFit estimation, validation;
  if (device.kind == "sim") {
    progress << "fitting " << plant_source << std::endl;
    progress << "identification trial (" << estimation_signal << ", +-" << config.identify.amplitude_deg << " deg, "
             << config.identify.duration_s << " s)" << std::endl;
    estimation = record_simulated_trial(config, estimation_signal, options.seed);
    progress << "validation trial (" << held_out_signal << ")" << std::endl;
    validation = record_simulated_trial(config, held_out_signal, options.seed + 1);
  } else {
    std::tie(estimation, validation) = record_rig_trials(config, device, options, estimation_signal, held_out_signal, progress);
  }
  const ArmModelFit fit = fit_arm_model(estimation.data, config.model, &stop_requested());
  const double validation_fit =
      normalized_fit_percent(validation.data.angle_rad, simulate_arm_angle(fit.model, validation.data));
  const double nominal_validation_fit =
      normalized_fit_percent(validation.data.angle_rad, simulate_arm_angle(config.model, validation.data));

  if (!options.write_model_path.empty()) {
    write_text_atomically(options.write_model_path,
                          with_model_section(existing_text, options.write_model_path, fit.model));
    progress << "wrote [model] to " << options.write_model_path << std::endl;
  }
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
        {"written_to", options.write_model_path.empty() ? nlohmann::json(nullptr) : nlohmann::json(options.write_model_path)}};
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
