// Arms with several joints (issue 14): the J-joint norm-optimal update in O(N) against the dense
// lifted form, and its set-up; the chain's mechanics (ArmChain) and the whole simulated J-joint arm
// (PneumaticArmChain) against real time. Results are written up in docs/benchmarks.md ("## Several joints").
#include <algorithm>
#include <array>
#include <cmath>
#include <span>
#include <random>
#include <vector>

#include <benchmark/benchmark.h>

#include "devices/simulated_arm.hpp"
#include "devices/simulated_arm_chain.hpp"
#include "engine/config/configuration.hpp"
#include "engine/rt/engine_core.hpp"
#include "engine/rt/engine_driver.hpp"
#include "engine/config/joint_learning_factory.hpp"
#include "engine/operator/learning_session.hpp"
#include "engine/model/pneumatic_arm_chain_parameters.hpp"
#include "engine/trial/trajectory.hpp"
#include "engine/model/arm_chain.hpp"
#include "engine/model/arm_chain_linearization.hpp"
#include "engine/model/arm_model.hpp"
#include "engine/learning/noilc_learned.hpp"
#include "engine/learning/noilc_mimo.hpp"
#include "engine/learning/noilc_mimo_constrained.hpp"
#include "engine/learning/noilc_mimo_dense.hpp"
#include "engine/learning/noilc_riccati.hpp"
#include "engine/model/pneumatic_arm_chain.hpp"

namespace bellows {
namespace {

constexpr double kSampleTime_s = 0.02;

/// J paper-type joints, each with the paper's model, coupled through a small off-diagonal input
/// gain (a full MIMO model: every block of A, B, C is used by the sweeps whatever its values).
MultiJointModel coupled_model(int joints) {
  const std::vector<DiscreteArmModel> arms(static_cast<std::size_t>(joints),
                                           discretize_arm_model(ModelParameters{}, kSampleTime_s));
  MultiJointModel model = block_diagonal_model(arms);
  for (int i = 0; i + 1 < joints; ++i) model.B(2 * i + 1, i + 1) = 0.2 * model.B(2 * i + 1, i);
  return model;
}

struct TrialData {
  Eigen::MatrixXd u_j, e_j, u_next;
  TrialData(int samples, int joints) : u_j(samples, joints), e_j(samples, joints), u_next(samples, joints) {
    std::mt19937 random(1);
    std::normal_distribution<double> normal(0.0, 1.0);
    for (Eigen::Index i = 0; i < u_j.size(); ++i) {
      u_j.data()[i] = 0.1 * normal(random);
      e_j.data()[i] = 0.05 * normal(random);
    }
  }
};

void BM_MultiJointUpdate(benchmark::State& state) {
  const int joints = static_cast<int>(state.range(0)), n = static_cast<int>(state.range(1));
  MultiJointNoilc law;
  if (law.setup(coupled_model(joints), MultiJointWeights::uniform(IlcParameters{}, joints), n) !=
      MultiJointNoilcStatus::kOk) {
    state.SkipWithError("setup failed");
    return;
  }
  TrialData data(n, joints);
  for (auto _ : state) {
    benchmark::DoNotOptimize(law.update(data.u_j, data.e_j, data.u_next));
    benchmark::DoNotOptimize(data.u_next.data());
  }
  state.counters["memory_MB"] = static_cast<double>(law.info().memory_bytes) / 1e6;
}
BENCHMARK(BM_MultiJointUpdate)
    ->Args({1, 400})
    ->Args({2, 400})
    ->Args({3, 400})
    ->Args({4, 400})
    ->Args({3, 12000})
    ->Unit(benchmark::kMicrosecond);

// The single-joint law (`noilc`) on the same data, for a comparison under the same machine load.
void BM_SingleJointUpdate(benchmark::State& state) {
  const int n = static_cast<int>(state.range(0));
  NormOptimalRiccati law(discretize_arm_model(ModelParameters{}, kSampleTime_s), IlcParameters{}, n);
  TrialData data(n, 1);
  Eigen::VectorXd u_next(n);
  for (auto _ : state) {
    law.update(data.u_j.col(0), data.e_j.col(0), u_next);
    benchmark::DoNotOptimize(u_next.data());
  }
}
BENCHMARK(BM_SingleJointUpdate)->Arg(400)->Unit(benchmark::kMicrosecond);

void BM_MultiJointSetup(benchmark::State& state) {
  const int joints = static_cast<int>(state.range(0)), n = static_cast<int>(state.range(1));
  const MultiJointModel model = coupled_model(joints);
  const MultiJointWeights weights = MultiJointWeights::uniform(IlcParameters{}, joints);
  for (auto _ : state) {
    MultiJointNoilc law;
    benchmark::DoNotOptimize(law.setup(model, weights, n));
  }
}
BENCHMARK(BM_MultiJointSetup)->Args({3, 400})->Args({3, 12000})->Unit(benchmark::kMicrosecond);

// The bounded update, cold: a large random error against +-0.05 bar bounds on every joint, restarted
// from the same u_j and a zero ADMM dual every time (many entries end on a bound), as
// BM_ConstrainedUpdate for one joint.
void BM_MultiJointConstrainedUpdate(benchmark::State& state) {
  const int joints = static_cast<int>(state.range(0)), n = static_cast<int>(state.range(1));
  MultiJointNoilcConstrained law;
  if (law.setup(coupled_model(joints), MultiJointWeights::uniform(IlcParameters{}, joints), n) !=
          MultiJointNoilcStatus::kOk ||
      law.set_bounds(Eigen::MatrixXd::Constant(n, joints, -0.05), Eigen::MatrixXd::Constant(n, joints, 0.05)) !=
          MultiJointNoilcStatus::kOk) {
    state.SkipWithError("setup failed");
    return;
  }
  TrialData data(n, joints);
  data.e_j *= 10.0;
  for (auto _ : state) {
    law.forget_warm_start();
    benchmark::DoNotOptimize(law.solve(data.u_j, data.e_j, data.u_next));
    benchmark::DoNotOptimize(data.u_next.data());
  }
  state.counters["admm_iterations"] = law.last_report().admm_iterations;
  state.counters["active_entries"] = law.last_report().active_entries;
}
BENCHMARK(BM_MultiJointConstrainedUpdate)->Args({3, 400})->Unit(benchmark::kMicrosecond);

// noilc-learned for J joints between two trials: refit from the last trial and the update, on the
// closed loop of the coupled model (5J prior states, J x (taps + 2) learned ones); J = 1 is the one-joint
// law (NoilcLearnedLaw wraps the same LearnedModelNoilc). The corrections alternate so that every call
// refits: the prior's response to the change of correction, the regressors, the ridge solve, the Riccati
// sweep on the refit model, the update.
void BM_MultiJointLearnedUpdateAndRefit(benchmark::State& state) {
  const int joints = static_cast<int>(state.range(0)), n = static_cast<int>(state.range(1));
  const Configuration config;
  const MultiJointModel model = coupled_model(joints);
  LearnedModelNoilc law(
      closed_loop_prior(model.A, model.B, kSampleTime_s, config.model.volume_gain_per_rad, config.controller),
      learned_noilc_settings(config.ilc), n);
  TrialData a(n, joints), b(n, joints);
  b.u_j = 0.5 * a.u_j.array() + 0.01;
  bool flip = false;
  for (auto _ : state) {
    const TrialData& d = flip ? b : a;
    flip = !flip;
    law.update(d.u_j, a.e_j, a.u_next);
    benchmark::DoNotOptimize(a.u_next.data());
  }
  state.counters["refitted"] = law.last_report().refitted ? 1.0 : 0.0;
}
BENCHMARK(BM_MultiJointLearnedUpdateAndRefit)
    ->Args({1, 400})
    ->Args({3, 400})
    ->Args({1, 12000})
    ->Args({3, 12000})
    ->Unit(benchmark::kMicrosecond);

void BM_MultiJointDenseUpdate(benchmark::State& state) {
  const int joints = static_cast<int>(state.range(0)), n = static_cast<int>(state.range(1));
  const MultiJointNoilcDense law(coupled_model(joints), MultiJointWeights::uniform(IlcParameters{}, joints), n);
  TrialData data(n, joints);
  for (auto _ : state) {
    data.u_next = law.update(data.u_j, data.e_j);
    benchmark::DoNotOptimize(data.u_next.data());
  }
}
BENCHMARK(BM_MultiJointDenseUpdate)->Args({3, 400})->Unit(benchmark::kMicrosecond);

// One simulated second of the chain's mechanics (RK4 at the spec's 0.1 ms), the pressure differences
// changing every 5 ms tick as a controller's would. Mechanics only: the bellows' pneumatics and the
// controllers are not in ArmChain. real_time_factor = simulated / wall-clock (CPU) time.
void BM_ArmChainSecond(benchmark::State& state) {
  const ChainParameters chain = chain_preset(state.range(0) == 2 ? "arm2" : "arm3");
  ArmChain arm(chain);
  const int J = chain.joints;
  constexpr double kTick_s = 0.005;
  for (auto _ : state) {
    for (int tick = 0; tick < 200; ++tick) {
      const double t = arm.state().time_s;
      JointVector dp(J);
      for (int i = 0; i < J; ++i) dp(i) = 0.1 + 0.1 * std::sin((3.0 + i) * t);
      arm.advance(kTick_s, dp);
    }
    benchmark::DoNotOptimize(arm.state().angle_rad.data());
  }
  state.counters["real_time_factor"] = benchmark::Counter(1.0, benchmark::Counter::kIsIterationInvariantRate);
}
BENCHMARK(BM_ArmChainSecond)->Arg(2)->Arg(3)->Unit(benchmark::kMillisecond);

// One simulated second of the whole simulated arm (PneumaticArmChain: the mechanics with every joint's
// bellows, valves and sensors), as the engine drives it: every 5 ms tick a reading and a new valve
// command per joint (duties moving like a pressure controller's, inlet or outlet per chamber, a few
// edges per period), then 5 ms of physics. Arg: joints (1: the single joint as a chain).
void BM_PneumaticArmChainSecond(benchmark::State& state) {
  const int J = static_cast<int>(state.range(0));
  const PneumaticChainParameters parameters =
      J == 1 ? pneumatic_chain_of(PlantParameters{}) : pneumatic_chain_preset(J == 2 ? "arm2" : "arm3");
  PneumaticArmChain arm(parameters, 1);
  constexpr double kTick_s = 0.005;
  std::array<BellowsDuties, kMaxJoints> duties{};
  double angle_sum = 0.0;
  for (auto _ : state) {
    for (int tick = 0; tick < 200; ++tick) {
      const PneumaticArmChain::Reading reading = arm.read_sensors();
      angle_sum += reading.angle_rad.sum();
      const double t = reading.time_s;
      for (int i = 0; i < J; ++i) {
        const double u = 0.5 * std::sin((3.0 + i) * t) + 0.3 * std::sin((11.0 + 2 * i) * t);
        auto& d = duties[static_cast<std::size_t>(i)];
        d.inlet = {std::max(0.0, u), std::max(0.0, -u)};
        d.outlet = {std::max(0.0, -0.8 * u), std::max(0.0, 0.8 * u)};
      }
      arm.write_valves(std::span<const BellowsDuties>(duties.data(), static_cast<std::size_t>(J)));
      arm.advance(kTick_s);
    }
  }
  benchmark::DoNotOptimize(angle_sum);
  state.counters["real_time_factor"] = benchmark::Counter(1.0, benchmark::Counter::kIsIterationInvariantRate);
}
BENCHMARK(BM_PneumaticArmChainSecond)->Arg(1)->Arg(2)->Arg(3)->Unit(benchmark::kMillisecond);

// The single-joint simulated arm (devices/simulated_arm) on the same drive, for comparison.
void BM_SimulatedArmSecond(benchmark::State& state) {
  SimulatedArm arm(PlantParameters{}, 1);
  double angle_sum = 0.0;
  for (auto _ : state) {
    for (int tick = 0; tick < 200; ++tick) {
      const SensorReading reading = arm.read_sensors();
      angle_sum += reading.joint[0].angle_rad;
      const double t = reading.time_s;
      const double u = 0.5 * std::sin(3.0 * t) + 0.3 * std::sin(11.0 * t);
      ValveCommand command;
      command.joint[0].inlet_duty = {std::max(0.0, u), std::max(0.0, -u)};
      command.joint[0].outlet_duty = {std::max(0.0, -0.8 * u), std::max(0.0, 0.8 * u)};
      arm.write_valves(command);
      arm.advance(0.005);
    }
  }
  benchmark::DoNotOptimize(angle_sum);
  state.counters["real_time_factor"] = benchmark::Counter(1.0, benchmark::Counter::kIsIterationInvariantRate);
}
BENCHMARK(BM_SimulatedArmSecond)->Unit(benchmark::kMillisecond);

void BM_ArmChainLinearization(benchmark::State& state) {
  const ArmChain arm(chain_preset("arm3"));
  const JointVector pose = JointVector::Constant(3, 0.3);
  for (auto _ : state) benchmark::DoNotOptimize(linearize_chain(arm, pose, kSampleTime_s).A.data());
}
BENCHMARK(BM_ArmChainLinearization)->Unit(benchmark::kMicrosecond);

/// `bellows run --config arm3.toml --trajectory paper3 --iterations 30 --no-save` without the process:
/// 31 trials of the 3-joint simulated arm on the simulated clock (each settling, then 8 s of paper3)
/// and the coupled J-joint update between them. Wall time per run of 30 iterations.
void BM_Arm3ThirtyIterationsHeadless(benchmark::State& state) {
  Configuration config;
  config.arm.preset = "arm3";
  const Trajectory paper3 = library_trajectory("paper3", config.timing.sample_s());
  const auto learning = make_joint_learning(config, discretize_arm_model(config.model, config.timing.sample_s()), 3,
                                            paper3.learning_samples());
  double last_rms_deg = 0.0;
  for (auto _ : state) {
    SimulatedArmChain arm(pneumatic_chain_of(config.plant, config.arm), 1);
    EngineCore core(arm, config.controller, config.timing, config.safety);
    SimulatedClock clock(core, arm);
    LearningSession session(clock, *learning, paper3, config.timing, config.controller);
    for (int i = 0; i <= 30; ++i) {
      last_rms_deg = session.run_trial().rms_deg;
      session.learn();
    }
  }
  state.counters["rms_deg_at_30"] = last_rms_deg;
}
BENCHMARK(BM_Arm3ThirtyIterationsHeadless)->Unit(benchmark::kMillisecond)->UseRealTime()->Iterations(3);

}  // namespace
}  // namespace bellows

BENCHMARK_MAIN();
