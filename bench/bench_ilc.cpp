// Learning-law update time and memory: the dense closed form against the O(N) Riccati form, and
// the constraint-aware law. Results are written up in docs/benchmarks.md ("## Learning laws").
#include <random>

#include <benchmark/benchmark.h>

#include "devices/simulated_arm.hpp"
#include "engine/model/arm_model.hpp"
#include "engine/config/configuration.hpp"
#include "engine/rt/engine_core.hpp"
#include "engine/operator/learning_session.hpp"
#include "engine/learning/noilc_constrained.hpp"
#include "engine/learning/noilc_dense.hpp"
#include "engine/learning/noilc_riccati.hpp"

namespace bellows {
namespace {

DiscreteArmModel model() { return discretize_arm_model(ModelParameters{}, 0.02); }

struct TrialData {
  Eigen::VectorXd u_j, e_j, u_next;
  explicit TrialData(int samples) : u_j(samples), e_j(samples), u_next(samples) {
    std::mt19937 random(1);
    std::normal_distribution<double> normal(0.0, 1.0);
    for (int t = 0; t < samples; ++t) {
      u_j(t) = 0.1 * normal(random);
      e_j(t) = 0.05 * normal(random);
    }
  }
};

void BM_RiccatiUpdate(benchmark::State& state) {
  const int n = static_cast<int>(state.range(0));
  NormOptimalRiccati law(model(), IlcParameters{}, n);
  TrialData data(n);
  for (auto _ : state) {
    law.update(data.u_j, data.e_j, data.u_next);
    benchmark::DoNotOptimize(data.u_next.data());
  }
  state.counters["memory_MB"] = static_cast<double>(law.memory_bytes()) / 1e6;
}
BENCHMARK(BM_RiccatiUpdate)->Arg(400)->Arg(4000)->Arg(12000)->Arg(40000)->Unit(benchmark::kMicrosecond);

void BM_DenseUpdate(benchmark::State& state) {
  const int n = static_cast<int>(state.range(0));
  NormOptimalDense law(model(), IlcParameters{}, n);
  TrialData data(n);
  for (auto _ : state) {
    law.update(data.u_j, data.e_j, data.u_next);
    benchmark::DoNotOptimize(data.u_next.data());
  }
  state.counters["memory_MB"] = static_cast<double>(law.memory_bytes()) / 1e6;
}
// N = 12000 would need 4.6 GB and 40000 51 GB: the dense form stops at 4000.
BENCHMARK(BM_DenseUpdate)->Arg(400)->Arg(4000)->Unit(benchmark::kMicrosecond);

void BM_RiccatiSetup(benchmark::State& state) {
  const int n = static_cast<int>(state.range(0));
  for (auto _ : state) benchmark::DoNotOptimize(NormOptimalRiccati(model(), IlcParameters{}, n).samples());
}
BENCHMARK(BM_RiccatiSetup)->Arg(400)->Arg(4000)->Arg(12000)->Arg(40000)->Unit(benchmark::kMicrosecond);

void BM_DenseSetup(benchmark::State& state) {
  const int n = static_cast<int>(state.range(0));
  for (auto _ : state) benchmark::DoNotOptimize(NormOptimalDense(model(), IlcParameters{}, n).samples());
}
BENCHMARK(BM_DenseSetup)->Arg(400)->Iterations(3)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_DenseSetup)->Arg(4000)->Iterations(1)->Unit(benchmark::kMillisecond);

// The constraint-aware update, cold: a large random error against +-0.05 bar bounds, restarted
// from the same u_j and a zero ADMM dual every time (most samples end on a bound). Plain bounds, no
// trial context: with one (zero feedback, a 0.05 bar limit) nearly every random u_j sits on the
// limit and its errors would be left out before the solve (396 of 400 were).
void BM_ConstrainedUpdate(benchmark::State& state) {
  const int n = static_cast<int>(state.range(0));
  NormOptimalConstrained law(model(), IlcParameters{}, n);
  TrialData data(n);
  data.e_j *= 10.0;
  law.set_bounds(Eigen::VectorXd::Constant(n, -0.05), Eigen::VectorXd::Constant(n, 0.05));
  for (auto _ : state) {
    law.forget_warm_start();
    law.update(data.u_j, data.e_j, data.u_next);
    benchmark::DoNotOptimize(data.u_next.data());
  }
  state.counters["admm_iterations"] = law.last_report().admm_iterations;
  state.counters["active_samples"] = law.last_report().active_samples;
  state.counters["unweighted_errors"] = law.last_report().unweighted_errors;
  state.counters["memory_MB"] = static_cast<double>(law.memory_bytes()) / 1e6;
}
BENCHMARK(BM_ConstrainedUpdate)->Arg(400)->Arg(12000)->Unit(benchmark::kMicrosecond);

// noilc-learned's update and refit: one benchmark for J = 1 and J = 3, BM_MultiJointLearnedUpdateAndRefit
// in bench_multi_joint.cpp (the one-joint law is the same LearnedModelNoilc).

// The constraint-aware update as it runs between trials: the paper scenario on the simulated arm
// after 40 trials (bounds active at the jumps), warm-started by the updates before it.
void BM_ConstrainedUpdatePaper(benchmark::State& state) {
  Configuration config;
  config.ilc.law = "noilc-constrained";
  const Trajectory trajectory = library_trajectory("paper", config.timing.sample_s());
  const int n = trajectory.learning_samples();
  NormOptimalConstrained law(discretize_arm_model(config.model, config.timing.sample_s()), config.ilc, n);
  SimulatedArm arm(config.plant, 1);
  EngineCore core(arm, config.controller, config.timing, config.safety);
  SimulatedClock clock(core, arm);
  LearningSession session(clock, law, trajectory, config.timing, config.controller);
  for (int j = 0; j < 40; ++j) {
    session.run_trial();
    session.learn();
  }
  session.run_trial();
  const Eigen::VectorXd u_j = session.correction_bar();
  const Eigen::VectorXd e_j = session.last_record().normalized_error();
  const Eigen::VectorXd feedback = session.last_record().joint_samples(0).u_pid_bar.head(n);
  Eigen::VectorXd u_next(n);
  law.set_input_context(feedback, config.controller.p_max_bar - config.controller.gas.ambient_bar);
  for (auto _ : state) {
    law.update(u_j, e_j, u_next);
    benchmark::DoNotOptimize(u_next.data());
  }
  state.counters["admm_iterations"] = law.last_report().admm_iterations;
  state.counters["active_samples"] = law.last_report().active_samples;
}
BENCHMARK(BM_ConstrainedUpdatePaper)->Unit(benchmark::kMicrosecond);

}  // namespace
}  // namespace bellows

BENCHMARK_MAIN();
