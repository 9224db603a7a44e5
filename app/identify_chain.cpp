#include "app/identify_chain.hpp"

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <ostream>
#include <vector>

#include <nlohmann/json.hpp>

#include "app/config_file.hpp"
#include "app/device_factory.hpp"
#include "app/identify_session.hpp"
#include "app/signals.hpp"
#include "app/toml_key_edit.hpp"
#include "devices/simulated_arm_chain.hpp"
#include "engine/model/arm_chain_linearization.hpp"
#include "engine/model/arm_chain_parameters.hpp"
#include "engine/operator/coupled_identification.hpp"
#include "engine/rt/engine_core.hpp"
#include "engine/base/errors.hpp"
#include "engine/operator/identification_trial.hpp"
#include "engine/model/pneumatic_arm_chain_parameters.hpp"
#include "engine/rt/realtime_loop.hpp"
#include "sessions/atomic_file.hpp"

namespace bellows {
namespace {

// The trial's operating point: the mean of its first 0.1 s, the arm at rest (the excitation fades
// in over its first second, identification_trial.cpp).
constexpr double kRest_s = 0.1;

/// Trials 0..J-1 excite joint 1..J with the identification signal, J..2J-1 with the held-out one.
struct ChainTrials {
  std::vector<Trajectory> excitations;
  std::vector<JointIdentificationData> estimation, validation;
};

std::string trial_line(const Configuration& config, const Trajectory& excitation, int joint, int joints,
                       const std::string& signal, bool held_out) {
  char line[240];
  std::snprintf(line, sizeof line, "joint %d of %d: %s trial (%s, +-%g deg, %g s), the other joints held", joint + 1,
                joints, held_out ? "held-out" : "identification", signal.c_str(), config.identify.amplitude_deg,
                excitation.duration_s());
  return line;
}

TrialRecord simulated_chain_trial(const Configuration& config, const Trajectory& excitation, std::uint64_t seed) {
  SimulatedArmChain arm(pneumatic_chain_of(config.plant, config.arm), seed);
  EngineCore core(arm, config.controller, config.timing, config.safety);
  SimulatedClock clock(core, arm);
  TrialRecord record;
  run_identification_trial(clock, excitation, config.timing, config.identify.max_abs_angle_deg, record,
                           &stop_requested());
  arm.vent();
  return record;
}

/// Every trial of `trials.excitations` in order: the simulated arm afresh for each (its seed the
/// trial's), a rig (lcm) all on one real-time loop, vented however it ends. The first trial is the
/// session's iteration 0; the session begins once the device serves.
void record_chain_trials(const Configuration& config, const DeviceParameters& device, const IdentifyOptions& options,
                         const std::string& signal, const std::string& held_out, IdentifySession& session,
                         ChainTrials& trials, std::ostream& progress) {
  const int J = arm_joint_count(config.arm);
  const auto take = [&](std::size_t index, const TrialRecord& record) {
    if (index == 0) session.save_estimation_trial(config, signal, record);
    JointIdentificationData data = joint_identification_data(record, config.controller, config.timing.tick_s, kRest_s);
    if (index > 0) {
      const bool later = index >= static_cast<std::size_t>(J);
      char line[200];
      std::snprintf(line, sizeof line,
                    "joint %d %s trial (%s): %lld samples every %g s (kept for the fit, not saved as an iteration)",
                    static_cast<int>(index) % J + 1, later ? "held-out" : "identification",
                    (later ? held_out : signal).c_str(), static_cast<long long>(data.angle_rad.rows()),
                    data.sample_time_s);
      session.record("identify-trial", line);
    }
    (index < static_cast<std::size_t>(J) ? trials.estimation : trials.validation).push_back(std::move(data));
  };
  const auto say = [&](std::size_t index) {
    const int joint = static_cast<int>(index) % J;
    const bool later = index >= static_cast<std::size_t>(J);
    progress << trial_line(config, trials.excitations[index], joint, J, later ? held_out : signal, later) << std::endl;
  };
  const auto begin = [&](const nlohmann::ordered_json& info) {
    session.begin(config, device.kind, info, trials.excitations.front(), held_out);
    if (!session.path().empty()) progress << "session " << session.path() << std::endl;
    if (!session.not_recorded().empty()) progress << "bellows: " << session.not_recorded() << std::endl;
  };
  if (device.kind == "sim") {
    begin({{"seed", options.seed}, {"arm", config.arm.name()}});
    for (std::size_t i = 0; i < trials.excitations.size(); ++i) {
      say(i);
      take(i, simulated_chain_trial(config, trials.excitations[i], options.seed + i));
    }
    return;
  }
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
  begin(rig->session_info());
  progress << "on " << device.kind << " " << rig->where() << std::endl;
  for (std::size_t i = 0; i < trials.excitations.size(); ++i) {
    say(i);
    TrialRecord record;
    run_identification_trial(loop, trials.excitations[i], config.timing, config.identify.max_abs_angle_deg, record,
                             &stop_requested());
    take(i, record);
  }
}

nlohmann::json matrix_json(const Eigen::MatrixXd& m) {
  nlohmann::json rows = nlohmann::json::array();
  for (Eigen::Index i = 0; i < m.rows(); ++i) {
    nlohmann::json row = nlohmann::json::array();
    for (Eigen::Index j = 0; j < m.cols(); ++j) row.push_back(m(i, j));
    rows.push_back(row);
  }
  return rows;
}

nlohmann::json vector_json(const JointVector& v) {
  nlohmann::json out = nlohmann::json::array();
  for (Eigen::Index i = 0; i < v.size(); ++i) out.push_back(v(i));
  return out;
}

nlohmann::json dynamics_json(const CoupledJointDynamics& d) {
  return {{"per_angle_per_s2", matrix_json(d.per_angle)},
          {"per_velocity_per_s", matrix_json(d.per_velocity)},
          {"per_bar_rad_per_s2", matrix_json(d.per_bar)},
          {"static_gain_rad_per_bar", matrix_json(d.static_gain_rad_per_bar())}};
}

std::string percents(const JointVector& v) {
  std::string text;
  char one[32];
  for (Eigen::Index i = 0; i < v.size(); ++i) {
    std::snprintf(one, sizeof one, "%s%.1f", i == 0 ? "" : " ", v(i));
    text += one;
  }
  return text + " %";
}

std::string matrix_text(const Eigen::MatrixXd& m) {
  std::string text = "[";
  char one[32];
  for (Eigen::Index i = 0; i < m.rows(); ++i) {
    text += i == 0 ? "[" : "; [";
    for (Eigen::Index j = 0; j < m.cols(); ++j) {
      std::snprintf(one, sizeof one, "%s%.3f", j == 0 ? "" : " ", m(i, j));
      text += one;
    }
    text += "]";
  }
  return text + "]";
}

/// One joint's single-joint fit and its check on the held-out trial.
struct JointFit {
  ModelParameters table;  // the [arm]'s own row: kappa, w0 straight, delta
  ArmModelFit fit;
  double validation_fit_percent = 0.0, table_validation_fit_percent = 0.0;
};

}  // namespace

std::string with_identified_model(const std::string& toml_text, const std::string& source_name,
                                  const IdentifiedArmParameters& identified, int joints) {
  std::string text = toml_text;
  for (int i = 0; i < joints; ++i) {
    const IdentifiedJointRow& row = identified.joint[static_cast<std::size_t>(i)];
    std::vector<std::pair<std::string, std::string>> values;
    for (int k = 0; k < joints; ++k) {
      const std::string j = std::to_string(k + 1);
      const auto at = static_cast<std::size_t>(k);
      values.emplace_back("per_angle_j" + j + "_per_s2", toml_number(row.per_angle_per_s2[at]));
      values.emplace_back("per_velocity_j" + j + "_per_s", toml_number(row.per_velocity_per_s[at]));
      values.emplace_back("per_bar_j" + j + "_rad_per_s2", toml_number(row.per_bar_rad_per_s2[at]));
    }
    text = with_table_values(text, "identified_joint" + std::to_string(i + 1), values, "fitted by bellows identify");
  }
  text =
      with_table_values(text, "ilc", {{"joint_model", "\"identified\""}}, "the coupled model bellows identify fitted");
  Configuration check;
  apply_config_toml(text, source_name, check);  // never write a file the loader would reject
  if (check.ilc.joint_model != "identified" || check.identified.joint[0].per_bar_rad_per_s2[0] !=
                                                   std::stod(toml_number(identified.joint[0].per_bar_rad_per_s2[0]))) {
    throw InputError("config " + source_name +
                     ": [identified_joint1] could not be updated in place (dotted or inline keys?)");
  }
  return text;
}

int identify_chain_command(const IdentifyOptions& options, const Configuration& config,
                           const std::string& write_model_text, std::ostream& out, std::ostream& progress) {
  const DeviceParameters device = resolve_device(options.device, config.device);
  require_driven_arm(config.arm, device.kind);  // the T7 carries one joint
  const bool write_model_exists =
      !options.write_model_path.empty() && std::filesystem::exists(options.write_model_path);
  if (!options.write_model_path.empty()) {  // checked before any trial runs
    Configuration written;
    apply_config_toml(write_model_text, options.write_model_path, written);
    if (written.arm.name() != config.arm.name()) {
      throw InputError("--write-model " + options.write_model_path + ": its arm is " +
                       (written.arm.has_chain() ? written.arm.name() : std::string("one joint")) + ", not " +
                       config.arm.name() + "; write the coupled model into the arm's configuration");
    }
  }
  const ChainParameters chain = chain_of(config.arm);
  const int J = chain.joints;
  const std::string signal = config.identify.signal;
  const std::string held_out = validation_signal(signal);
  const double sample_s = config.timing.sample_s();
  ChainTrials trials;
  for (const std::string& s : {signal, held_out}) {
    const Trajectory one = identification_trajectory(s, config.identify, sample_s);
    for (int k = 0; k < J; ++k) trials.excitations.push_back(joint_excitation(one, k, J));
  }
  IdentifySession session(options.no_save, options.data_dir, options.session_name);
  std::vector<JointFit> joints(static_cast<std::size_t>(J));
  CoupledModelFit coupled;
  CoupledJointDynamics linearization, independent;
  JointVector coupled_validation, linearization_validation, independent_validation, linearization_fit;
  double markov_relative_gap = 0.0, static_gain_relative_gap = 0.0;
  const int markov_samples = static_cast<int>(std::lround(config.identify.duration_s / sample_s));
  try {
    progress << "identifying " << config.arm.name() << ": " << J << " joints, each excited in turn" << std::endl;
    record_chain_trials(config, device, options, signal, held_out, session, trials, progress);
    for (int k = 0; k < J; ++k) {
      JointFit& j = joints[static_cast<std::size_t>(k)];
      const ChainLink& link = chain.links[static_cast<std::size_t>(k)];
      j.table = {link.kappa_rad_per_bar, link.omega0_straight_rad_per_s, link.damping_ratio};
      j.fit = fit_arm_model(single_joint_data(trials.estimation[static_cast<std::size_t>(k)], k), j.table,
                            &stop_requested());
      const IdentificationData held = single_joint_data(trials.validation[static_cast<std::size_t>(k)], k);
      j.validation_fit_percent = normalized_fit_percent(held.angle_rad, simulate_arm_angle(j.fit.model, held));
      j.table_validation_fit_percent = normalized_fit_percent(held.angle_rad, simulate_arm_angle(j.table, held));
      char line[320];
      std::snprintf(
          line, sizeof line,
          "joint %d: kappa %.6g rad/bar, omega0 %.6g 1/s, damping %.6g: fit %.1f %%, %.1f %% on the held-out trial "
          "(the arm's own row: %.1f %%)",
          k + 1, j.fit.model.kappa_rad_per_bar, j.fit.model.omega0_rad_per_s, j.fit.model.damping, j.fit.fit_percent,
          j.validation_fit_percent, j.table_validation_fit_percent);
      session.record("identify-fit", line);
    }
    std::vector<ModelParameters> fitted;
    fitted.reserve(joints.size());
    for (const JointFit& j : joints) fitted.push_back(j.fit.model);
    independent = independent_dynamics(fitted);
    progress << "fitting the coupled model (" << 2 * J << " states) on the " << J << " identification trials"
             << std::endl;
    coupled = fit_coupled_model(trials.estimation, independent, &stop_requested());
    coupled_validation = joint_fit_percent(coupled.dynamics, trials.validation);
    independent_validation = joint_fit_percent(independent, trials.validation);
    linearization = chain_dynamics(ArmChain(chain), JointVector::Zero(J));
    linearization_fit = joint_fit_percent(linearization, trials.estimation);
    linearization_validation = joint_fit_percent(linearization, trials.validation);
    markov_relative_gap = markov_gap(discretize_joint_dynamics(coupled.dynamics, sample_s),
                                     discretize_joint_dynamics(linearization, sample_s), markov_samples);
    const Eigen::MatrixXd lin_gain = linearization.static_gain_rad_per_bar();
    static_gain_relative_gap = (coupled.dynamics.static_gain_rad_per_bar() - lin_gain).norm() / lin_gain.norm();
    session.record("identify-fit", "coupled model: fit " + percents(coupled.fit_percent) + ", " +
                                       percents(coupled_validation) + " on the held-out trials (linearization " +
                                       percents(linearization_validation) + ", independent joints " +
                                       percents(independent_validation) + ")");
    char gap[200];
    std::snprintf(
        gap, sizeof gap,
        "coupled model vs the linearization stretched out: %.1f %% (Markov parameters), %.1f %% (static gain)",
        100.0 * markov_relative_gap, 100.0 * static_gain_relative_gap);
    session.record("identify-gap", gap);
    if (!options.write_model_path.empty()) {
      // Created (a file that appeared meanwhile is refused), or the file read before the trials, edited.
      write_file_atomic(
          options.write_model_path,
          with_identified_model(write_model_text, options.write_model_path, identified_parameters(coupled.dynamics), J),
          DirectorySync::kNow, write_model_exists ? Replace::kAllowed : Replace::kRefused);
      progress << "wrote [identified_joint1.." << J << "] and [ilc] joint_model = \"identified\" to "
               << options.write_model_path << std::endl;
      session.record("model-written", "[identified_joint1.." + std::to_string(J) +
                                          "] and [ilc] joint_model written into the configuration " +
                                          options.write_model_path);
    }
  } catch (const std::exception& error) {
    session.record("fault", error.what());  // the trials so far stay in the session
    throw;
  }
  session.record("finish", options.write_model_path.empty()
                               ? "identified; the model was written nowhere (--write-model FILE)"
                               : "identified; the coupled model is in " + options.write_model_path);
  if (options.json) {
    nlohmann::json per_joint = nlohmann::json::array();
    for (int k = 0; k < J; ++k) {
      const JointFit& j = joints[static_cast<std::size_t>(k)];
      per_joint.push_back({{"joint", k + 1},
                           {"model", model_json(j.fit.model)},
                           {"initial_model", model_json(j.fit.initial)},
                           {"arm_model", model_json(j.table)},
                           {"fit_percent", j.fit.fit_percent},
                           {"validation_fit_percent", j.validation_fit_percent},
                           {"arm_model_validation_fit_percent", j.table_validation_fit_percent},
                           {"rms_residual_deg", j.fit.rms_residual_deg},
                           {"iterations", j.fit.iterations},
                           {"converged", j.fit.converged}});
    }
    nlohmann::json coupled_json = dynamics_json(coupled.dynamics);
    coupled_json.update({{"states", 2 * J},
                         {"fit_percent", vector_json(coupled.fit_percent)},
                         {"validation_fit_percent", vector_json(coupled_validation)},
                         {"rms_residual_deg", coupled.rms_residual_deg},
                         {"iterations", coupled.iterations},
                         {"converged", coupled.converged}});
    nlohmann::json linearization_json = dynamics_json(linearization);
    linearization_json.update({{"pose_rad", vector_json(JointVector::Zero(J))},
                               {"fit_percent", vector_json(linearization_fit)},
                               {"validation_fit_percent", vector_json(linearization_validation)}});
    const nlohmann::json report = {
        {"device", device.kind},
        {"arm", config.arm.name()},
        {"joints", J},
        {"signal", signal},
        {"validation_signal", held_out},
        {"samples", trials.estimation.front().angle_rad.rows()},
        {"sample_time_s", trials.estimation.front().sample_time_s},
        {"joint_models", per_joint},
        {"coupled_model", coupled_json},
        {"independent_validation_fit_percent", vector_json(independent_validation)},
        {"linearization", linearization_json},
        {"linearization_gap",
         {{"markov_relative", markov_relative_gap},
          {"markov_samples", markov_samples},
          {"sample_time_s", sample_s},
          {"static_gain_relative", static_gain_relative_gap}}},
        {"written_to",
         options.write_model_path.empty() ? nlohmann::json(nullptr) : nlohmann::json(options.write_model_path)},
        {"written_as", options.write_model_path.empty() ? nlohmann::json(nullptr) : nlohmann::json("config")},
        {"session", session.path().empty() ? nlohmann::json(nullptr) : nlohmann::json(session.path())}};
    out << report.dump() << std::endl;
    return 0;
  }
  char text[400];
  for (int k = 0; k < J; ++k) {
    const JointFit& j = joints[static_cast<std::size_t>(k)];
    std::snprintf(
        text, sizeof text,
        "joint %d: kappa %.4f rad/bar  omega0 %.4f 1/s  damping %.4f  fit %.1f %% on %s, %.1f %% on held-out %s "
        "(the arm's own row: %.1f %%), rms residual %.3f deg%s\n",
        k + 1, j.fit.model.kappa_rad_per_bar, j.fit.model.omega0_rad_per_s, j.fit.model.damping, j.fit.fit_percent,
        signal.c_str(), j.validation_fit_percent, held_out.c_str(), j.table_validation_fit_percent,
        j.fit.rms_residual_deg, j.fit.converged ? "" : " (not converged)");
    out << text;
  }
  out << "coupled model (" << 2 * J << " states): fit " << percents(coupled.fit_percent) << " on " << signal << ", "
      << percents(coupled_validation) << " on held-out " << held_out << " (linearization "
      << percents(linearization_validation) << ", independent joints " << percents(independent_validation) << ")";
  std::snprintf(text, sizeof text, ", rms residual %.3f deg, %d iterations%s\n", coupled.rms_residual_deg,
                coupled.iterations, coupled.converged ? "" : " (not converged)");
  out << text;
  std::snprintf(text, sizeof text,
                "gap to the linearization stretched out: %.1f %% (Markov parameters, %d samples of %g s), %.1f %% "
                "(static gain)\n",
                100.0 * markov_relative_gap, markov_samples, sample_s, 100.0 * static_gain_relative_gap);
  out << text;
  out << "static gain rad/bar: identified " << matrix_text(coupled.dynamics.static_gain_rad_per_bar())
      << ", linearized " << matrix_text(linearization.static_gain_rad_per_bar()) << "\n";
  return 0;
}

}  // namespace bellows
