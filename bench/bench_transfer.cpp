// Learning transfer: the time to compute a transfer from two 30-iteration sessions (paper, steps),
// and, with --table, the comparison of every method on the five unseen trajectories that
// docs/learning-laws.md ("Transfer") reports.
#include <algorithm>
#include <cstdio>
#include <cstring>

#include <benchmark/benchmark.h>

#include "engine/config/configuration.hpp"
#include "tests/test_transfer_scenarios.hpp"

namespace {

using namespace bellows;
using namespace bellows::testing;

std::vector<TransferSource> trained_sources(const Configuration& config, int iterations) {
  const double t = config.timing.sample_s();
  return {run_learning(config, library_trajectory("paper", t), iterations).source,
          run_learning(config, library_trajectory("steps", t), iterations).source};
}

void BM_TransferFromTwoSessions(benchmark::State& state) {
  const Configuration config;
  const std::vector<TransferSource> sources = trained_sources(config, 30);
  const Trajectory target = unseen_trajectories(config.timing.sample_s())[1];
  for (auto _ : state) {
    LearningTransfer transfer;
    transfer.setup(sources, config.controller, config.timing.sample_s());
    TransferResult result = transfer.solve(target);
    benchmark::DoNotOptimize(result.correction_bar.data());
  }
}
BENCHMARK(BM_TransferFromTwoSessions)->Unit(benchmark::kMillisecond);

double at(const std::vector<double>& v, std::size_t i) { return i < v.size() ? v[i] : NAN; }

int print_table(int iterations) {
  const Configuration config;
  const double t = config.timing.sample_s();
  const std::vector<TransferSource> sources = trained_sources(config, 30);
  std::printf(
      "| trajectory | method | status | predicted / measured first-trial RMS (deg) | first-trial ratio | "
      "RMS at 1 / 3 / 5 / 10 (deg) |\n|---|---|---|---|---|---|\n");
  for (const Trajectory& target : unseen_trajectories(t)) {
    const LearningRun scratch = run_learning(config, target, iterations);
    std::printf("| %s | scratch | feedback only | - / %.2f | 1.00 | %.2f / %.2f / %.2f / %.2f |\n", target.name.c_str(),
                scratch.rms_deg[0], at(scratch.rms_deg, 1), at(scratch.rms_deg, 3), at(scratch.rms_deg, 5),
                at(scratch.rms_deg, 10));
    for (const char* name : {"reference-fir", "basis", "inverse-fir", "auto"}) {
      TransferSettings settings;
      settings.method = parse_transfer_method(name);
      LearningTransfer transfer(settings);
      transfer.setup(sources, config.controller, t);
      const TransferResult r = transfer.solve(target);
      const LearningRun run = run_learning(config, target, iterations, r.correction_bar);
      std::printf("| %s | %s%s%s | %s | %.2f / %.2f | %.2f | %.2f / %.2f / %.2f / %.2f |\n", target.name.c_str(), name,
                  std::strcmp(name, "auto") == 0 ? " -> " : "", std::strcmp(name, "auto") == 0 ? r.method.c_str() : "",
                  r.status == TransferStatus::kTransferred ? "transferred" : r.reason.c_str(), r.predicted_rms_deg,
                  run.rms_deg[0], run.rms_deg[0] / scratch.rms_deg[0], at(run.rms_deg, 1), at(run.rms_deg, 3),
                  at(run.rms_deg, 5), at(run.rms_deg, 10));
      std::fflush(stdout);
    }
  }
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  for (int i = 1; i < argc; ++i) {
    if (std::strcmp(argv[i], "--table") == 0) return print_table(10);
  }
  benchmark::Initialize(&argc, argv);
  benchmark::RunSpecifiedBenchmarks();
  return 0;
}
