// Engine benchmarks: the simulated arm's speed, one ILC update, and a whole headless paper run.
#include <benchmark/benchmark.h>

#include "devices/simulated_arm.hpp"
#include "engine/control/control_core.hpp"
#include "engine/rt/engine_core.hpp"
#include "engine/operator/learning_session.hpp"
#include "engine/learning/noilc_dense.hpp"

namespace bellows {
namespace {

// Closed-loop simulated seconds per wall second (controllers included), holding then tracking.
void BM_SimulatedArmClosedLoop(benchmark::State& state) {
  const PlantParameters plant;
  const ControllerParameters controller;
  const TimingParameters timing;
  SimulatedArm arm(plant, 1);
  ControlCore core(controller, timing);
  const long ticks_per_second = std::lround(1.0 / timing.tick_s);
  auto run_ticks = [&](long ticks) {
    for (long i = 0; i < ticks; ++i) {
      arm.write_valves(core.tick(arm.read_sensors()));
      arm.advance(timing.tick_s);
    }
  };
  double simulated_s = 0.0;
  for (auto _ : state) {
    core.hold(0.3);
    run_ticks(ticks_per_second);
    core.hold(-0.3);
    run_ticks(ticks_per_second);
    simulated_s += 2.0;
  }
  state.counters["sim_s_per_wall_s"] = benchmark::Counter(simulated_s, benchmark::Counter::kIsRate);
}
BENCHMARK(BM_SimulatedArmClosedLoop)->Unit(benchmark::kMillisecond);

void BM_NoilcDenseUpdate(benchmark::State& state) {
  const int n = static_cast<int>(state.range(0));
  NormOptimalDense law(discretize_arm_model(ModelParameters{}, 0.02), IlcParameters{}, n);
  const Eigen::VectorXd u = Eigen::VectorXd::LinSpaced(n, -0.1, 0.1);
  const Eigen::VectorXd e = Eigen::VectorXd::LinSpaced(n, 0.05, -0.02);
  Eigen::VectorXd next(n);
  for (auto _ : state) {
    law.update(u, e, next);
    benchmark::DoNotOptimize(next.data());
  }
}
BENCHMARK(BM_NoilcDenseUpdate)->Arg(400)->Unit(benchmark::kMicrosecond);

void BM_NoilcDenseSetup(benchmark::State& state) {
  const int n = static_cast<int>(state.range(0));
  const DiscreteArmModel model = discretize_arm_model(ModelParameters{}, 0.02);
  for (auto _ : state) {
    NormOptimalDense law(model, IlcParameters{}, n);
    benchmark::DoNotOptimize(&law);
  }
}
BENCHMARK(BM_NoilcDenseSetup)->Arg(400)->Unit(benchmark::kMillisecond);

// The target: 30 learning iterations of the paper trajectory, headless (31 trials).
void BM_PaperRun30Iterations(benchmark::State& state) {
  const PlantParameters plant;
  const ControllerParameters controller;
  const TimingParameters timing;
  const Trajectory paper = library_trajectory("paper", timing.sample_s());
  for (auto _ : state) {
    SimulatedArm arm(plant, 1);
    EngineCore core(arm, controller, timing, SafetyParameters{});
    SimulatedClock clock(core, arm);
    NormOptimalDense law(discretize_arm_model(ModelParameters{}, timing.sample_s()), IlcParameters{},
                         paper.learning_samples());
    LearningSession session(clock, law, paper, timing, controller);
    for (int i = 0; i <= 30; ++i) {
      benchmark::DoNotOptimize(session.run_trial().rms_deg);
      if (i < 30) session.learn();
    }
  }
}
BENCHMARK(BM_PaperRun30Iterations)->Unit(benchmark::kMillisecond)->Iterations(3);

}  // namespace
}  // namespace bellows

BENCHMARK_MAIN();
