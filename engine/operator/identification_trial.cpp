#include "engine/operator/identification_trial.hpp"

#include <cmath>
#include <numbers>
#include <sstream>

#include "engine/base/errors.hpp"
#include "engine/operator/trial_runner.hpp"
#include "engine/base/units.hpp"

namespace bellows {
namespace {
constexpr double kFade_s = 1.0;
// Steps: each level change is a 0.15 s trapezoidal move at the paper's peak acceleration.
constexpr double kStepMove_s = 0.15, kStepAcceleration_deg_per_s2 = 12000.0;
constexpr double kGoldenRatioFraction = 0.6180339887498949;
}  // namespace

std::string validation_signal(const std::string& signal) {
  if (signal == "chirp") return "steps";
  if (signal == "steps") return "chirp";
  throw InputError("[identify] signal = '" + signal + "': unknown excitation (known: chirp, steps)");
}

Trajectory identification_trajectory(const std::string& signal, const IdentificationParameters& p,
                                     double sample_time_s) {
  validation_signal(signal);  // checks the name
  if (p.amplitude_deg >= p.max_abs_angle_deg) {
    throw InputError("[identify] amplitude_deg must be below [identify] max_abs_angle_deg");
  }
  if (p.duration_s < 2.0 * kFade_s + 1.0) throw InputError("[identify] duration_s must be at least 3 s");
  const int samples = static_cast<int>(std::lround(p.duration_s / sample_time_s));
  if (signal == "chirp") {
    if (!(p.chirp_end_hz > p.chirp_start_hz) || p.chirp_end_hz >= 0.5 / sample_time_s) {
      throw InputError("[identify] chirp_end_hz must lie above chirp_start_hz and below the Nyquist frequency");
    }
    Trajectory t{"identify-chirp", sample_time_s, {Eigen::VectorXd(samples + 1)}};
    const double ratio = p.chirp_end_hz / p.chirp_start_hz;
    const double D = p.duration_s;
    for (int k = 0; k <= samples; ++k) {
      const double time = k * sample_time_s;
      const double phase = p.chirp_start_hz * D / std::log(ratio) * (std::pow(ratio, time / D) - 1.0);
      const double edge = std::min(time, D - time);
      const double fade =
          edge >= kFade_s ? 1.0 : 0.5 * (1.0 - std::cos(std::numbers::pi * std::max(edge, 0.0) / kFade_s));
      t.joint(0)(k) = fade * p.amplitude_deg * kRadPerDeg * std::sin(2.0 * std::numbers::pi * phase);
    }
    return t;
  }
  if (!(p.step_hold_s > kStepMove_s)) throw InputError("[identify] step_hold_s must exceed the 0.15 s move");
  std::vector<TrapezoidalMove> moves;
  double level = 0.0;
  for (int i = 1; kFade_s + i * p.step_hold_s < p.duration_s - kFade_s; ++i) {
    const double fraction = std::fmod(i * kGoldenRatioFraction, 1.0);
    const double next = p.amplitude_deg * (2.0 * fraction - 1.0);
    moves.push_back({kFade_s + (i - 1) * p.step_hold_s, level, next, kStepMove_s, kStepAcceleration_deg_per_s2});
    level = next;
  }
  moves.push_back({p.duration_s - kFade_s, level, 0.0, kStepMove_s, kStepAcceleration_deg_per_s2});
  return trajectory_from_moves("identify-steps", 0.0, moves, p.duration_s, sample_time_s);
}

Trajectory joint_excitation(const Trajectory& excitation, int joint, int joints) {
  if (!valid_joint_count(joints) || joint < 0 || joint >= joints || excitation.joints() != 1) {
    throw InputError("identification: joint " + std::to_string(joint + 1) + " of " + std::to_string(joints) +
                     " cannot be excited");
  }
  const Eigen::VectorXd rest = Eigen::VectorXd::Zero(excitation.joint(0).size());
  Trajectory t{excitation.name + "-joint" + std::to_string(joint + 1), excitation.sample_time_s,
               std::vector<Eigen::VectorXd>(static_cast<std::size_t>(joints), rest)};
  t.joint(joint) = excitation.joint(0);
  return t;
}

void run_identification_trial(EngineDriver& driver, const Trajectory& excitation, const TimingParameters& timing,
                              double max_abs_angle_deg, TrialRecord& record, StopFlag stop) {
  // Through the engine like any trial (engine/operator/trial_runner): armed, guarded, the record
  // prepared outside the loop; every joint of the excitation. The angle bound is this trial's own
  // guard, looked at after every poll (every tick on the simulated clock).
  if (!driver.core().send(EngineCommand::select_trajectory(excitation))) {
    throw std::runtime_error("identification: the engine's command queue is full");
  }
  const double bound_rad = max_abs_angle_deg * kRadPerDeg;
  const int joints = excitation.joints();
  const Eigen::MatrixXd no_correction = Eigen::MatrixXd::Zero(excitation.learning_samples(), joints);
  TrialRunner runner(driver.core(), timing);
  runner.start(excitation, no_correction, record, TrialRunner::Arming::kIfNeeded);
  std::string left_bound;  // why the guard stopped the trial
  const TrialStatus& status = runner.run_to_completion(driver, stop, [&](const TickRecord& tick) {
    for (int j = 0; j < joints; ++j) {
      const double angle_rad = tick.reading.joint[static_cast<std::size_t>(j)].angle_rad;
      if (std::abs(angle_rad) <= bound_rad) continue;
      std::ostringstream message;
      message << "identification aborted, valves vented: "
              << (joints > 1 ? "joint " + std::to_string(j + 1) + "'s " : std::string()) << "angle "
              << angle_rad / kRadPerDeg << " deg at t = " << tick.time_s << " s left +-" << max_abs_angle_deg
              << " deg; lower [identify] amplitude_deg";
      left_bound = message.str();
      runner.cancel();
      return;
    }
  });
  // The fault by its name too: "a fault is latched" alone does not say which.
  const std::string named =
      status.fault != FaultCode::kNone ? std::string(" (") + fault_name(status.fault) + ")" : std::string();
  switch (status.phase) {
    case TrialPhase::kDone:
      return;
    case TrialPhase::kNotSent:
      throw std::runtime_error("identification: the engine's command queue is full");
    case TrialPhase::kRefused:
      throw EngineFault(status.fault, "identification refused by the engine: " + status.message + named);
    case TrialPhase::kCancelled:
      if (!left_bound.empty()) throw InputError(left_bound);
      throw Cancelled("identification stopped by a signal, valves vented");
    default:
      throw EngineFault(status.fault, "identification aborted: " + status.message + named);
  }
}

}  // namespace bellows
