// Learning-transfer scenarios shared by tests/test_transfer.cpp and bench/bench_transfer.cpp:
// training sessions on the simulated arm (simulated clock, deterministic) and five unseen
// trajectories of different character, defined here and not in the library.
#pragma once

#include <cmath>
#include <memory>
#include <numbers>
#include <string>
#include <vector>

#include "devices/simulated_arm.hpp"
#include "engine/model/arm_model.hpp"
#include "engine/rt/engine_core.hpp"
#include "engine/rt/engine_driver.hpp"
#include "engine/config/learning_law_factory.hpp"
#include "engine/operator/learning_session.hpp"
#include "engine/config/learning_transfer.hpp"
#include "engine/trial/trajectory.hpp"

namespace bellows::testing {

inline constexpr double kDegToRad = std::numbers::pi / 180.0;

/// A trajectory from a function of time (deg), `duration_s` long.
template <typename AngleOfTime>
Trajectory trajectory_of(const std::string& name, double duration_s, double sample_time_s, AngleOfTime angle_deg) {
  const int n = static_cast<int>(std::lround(duration_s / sample_time_s));
  Trajectory t{name, sample_time_s, {Eigen::VectorXd(n + 1)}};
  for (int k = 0; k <= n; ++k) t.joint(0)(k) = angle_deg(k * sample_time_s) * kDegToRad;
  validate_trajectory(t, TrajectoryLimits{});
  return t;
}

/// Raised-cosine fade over `fade_s` at both ends.
inline double fade(double t, double duration_s, double fade_s) {
  const double edge = std::min(t, duration_s - t);
  return edge >= fade_s ? 1.0 : 0.5 * (1.0 - std::cos(std::numbers::pi * std::max(edge, 0.0) / fade_s));
}

/// The five unseen trajectories: fast steps, smooth random motion, a faster sine, a triangle,
/// pick-and-place moves.
inline std::vector<Trajectory> unseen_trajectories(double sample_time_s) {
  std::vector<Trajectory> out;
  out.push_back(trajectory_from_moves("fast-steps", 0.0,
                                      {{0.4, 0, 25, 0.15, 12000},
                                       {1.2, 25, -15, 0.15, 12000},
                                       {2.0, -15, 35, 0.15, 12000},
                                       {2.8, 35, 10, 0.15, 12000},
                                       {3.6, 10, -35, 0.15, 12000},
                                       {4.4, -35, 0, 0.15, 12000}},
                                      6.0, sample_time_s));
  out.push_back(trajectory_of("smooth-random", 8.0, sample_time_s, [](double t) {
    // Fixed "random" amplitudes, frequencies and phases: a band-limited random motion.
    const double a[] = {14, 11, 8, 6}, f[] = {0.23, 0.47, 0.71, 1.09}, p[] = {0.4, 2.1, 4.0, 5.3};
    double s = 0;
    for (int i = 0; i < 4; ++i) s += a[i] * std::sin(2 * std::numbers::pi * f[i] * t + p[i]) - a[i] * std::sin(p[i]);
    return fade(t, 8.0, 1.0) * s;
  }));
  out.push_back(trajectory_of("fast-sine", 6.0, sample_time_s, [](double t) {
    return fade(t, 6.0, 0.8) * 25.0 * std::sin(2 * std::numbers::pi * 1.2 * t);
  }));
  out.push_back(trajectory_of("triangle", 8.0, sample_time_s, [](double t) {
    // +-35 deg at 0.5 Hz (140 deg/s), starting and ending at rest at 0.
    if (t < 1.0 || t > 7.0) return 0.0;
    const double phase = std::fmod(t - 1.0, 2.0);
    return phase < 0.5 ? 70.0 * phase : (phase < 1.5 ? 35.0 - 70.0 * (phase - 0.5) : -35.0 + 70.0 * (phase - 1.5));
  }));
  out.push_back(trajectory_from_moves("pick-and-place", 0.0,
                                      {{0.5, 0, 50, 0.35, 6000},
                                       {1.7, 50, -40, 0.4, 6000},
                                       {3.1, -40, 20, 0.35, 6000},
                                       {4.5, 20, -25, 0.35, 6000},
                                       {5.9, -25, 0, 0.3, 6000}},
                                      8.0, sample_time_s));
  return out;
}

/// One learning run on a fresh simulated arm: RMS per trial and every trial as transfer data.
struct LearningRun {
  std::vector<double> rms_deg;
  TransferSource source;
};

/// `iterations` learning iterations after the first trial, which runs with `first_correction`
/// (feedback only when empty). `plant` lets a test make the arm differ from the model.
inline LearningRun run_learning(const Configuration& config, const Trajectory& trajectory, int iterations,
                                const Eigen::VectorXd& first_correction = {}, std::uint64_t seed = 1) {
  const int n = trajectory.learning_samples();
  const auto law = make_learning_law(config, discretize_arm_model(config.model, config.timing.sample_s()), n);
  SimulatedArm arm(config.plant, seed);
  EngineCore core(arm, config.controller, config.timing, config.safety);
  SimulatedClock clock(core, arm);
  LearningSession session(clock, *law, trajectory, config.timing, config.controller);
  if (first_correction.size() == n) session.set_correction(first_correction, 0);
  LearningRun run;
  run.source.name = trajectory.name;
  run.source.trajectory = trajectory;
  run.source.controller = config.controller;
  for (int j = 0; j <= iterations; ++j) {
    run.rms_deg.push_back(session.run_trial().rms_deg);
    const TrialSamples& s = session.last_record().joint_samples(0);
    run.source.trials.push_back({s.u_ilc_bar.head(n), s.u_pid_bar.head(n), s.angle_rad.head(n + 1)});
    if (j < iterations) session.learn();
  }
  return run;
}

}  // namespace bellows::testing
