// Saving and loading a paper session: 31 trials (the feedback-only one and 30 learning
// iterations) of the paper trajectory, 400 samples and 1600 ticks each, simulated once.
// Saving includes every fsync; results in docs/benchmarks.md, "Sessions".
#include <unistd.h>

#include <filesystem>

#include <benchmark/benchmark.h>

#include "devices/simulated_arm.hpp"
#include "engine/model/arm_model.hpp"
#include "engine/rt/engine_core.hpp"
#include "engine/rt/engine_driver.hpp"
#include "engine/config/learning_law_factory.hpp"
#include "engine/operator/learning_session.hpp"
#include "sessions/iteration_files.hpp"
#include "sessions/session_export.hpp"
#include "sessions/session_store.hpp"
#include "sessions/session_writer.hpp"

namespace bellows {
namespace {

namespace fs = std::filesystem;

const Session& paper_session() {
  static const Session session = [] {
    const Configuration config;
    const Trajectory trajectory = library_trajectory("paper", config.timing.sample_s());
    const DiscreteArmModel model = discretize_arm_model(config.model, config.timing.sample_s());
    const auto law = make_learning_law(config, model, trajectory.learning_samples());
    SimulatedArm arm(config.plant, 1);
    EngineCore core(arm, config.controller, config.timing, config.safety);
    SimulatedClock clock(core, arm);
    LearningSession learning(clock, *law, trajectory, config.timing, config.controller);
    Session s;
    s.manifest.program_version = program_version();
    s.manifest.name = "paper";
    s.manifest.device = arm.name();
    s.manifest.device_info = {{"seed", 1}};
    s.manifest.started_utc = utc_now();
    s.manifest.configuration = config;
    s.manifest.trajectory_name = trajectory.name;
    s.manifest.trajectory_samples = trajectory.learning_samples();
    s.trajectory = trajectory;
    for (int i = 0; i <= 30; ++i) {
      const IterationSummary summary = learning.run_trial();
      learning.learn();
      s.iterations.push_back({learning.last_record(), learning.correction_bar()});
      s.manifest.iterations.push_back({summary, utc_now()});
      s.manifest.resume = ResumeState{core.control().state(), {{"time_s", arm.state().time_s}}, clock.ticks()};
    }
    return s;
  }();
  return session;
}

fs::path scratch_dir() {
  static const fs::path dir = [] {
    std::string pattern = (fs::temp_directory_path() / "bellows-bench-XXXXXX").string();
    if (::mkdtemp(pattern.data()) == nullptr) throw std::runtime_error("mkdtemp failed");
    return fs::path(pattern);
  }();
  return dir;
}

void BM_SavePaperSession(benchmark::State& state) {
  const Session& session = paper_session();
  int count = 0;
  for (auto _ : state) {
    const fs::path dir = scratch_dir() / ("save-" + std::to_string(count++));
    save_session(session, dir);
    state.PauseTiming();
    fs::remove_all(dir);
    state.ResumeTiming();
  }
}
BENCHMARK(BM_SavePaperSession)->Unit(benchmark::kMillisecond)->UseRealTime();

void BM_LoadPaperSession(benchmark::State& state) {
  const fs::path dir = scratch_dir() / "load";
  if (!fs::exists(dir)) save_session(paper_session(), dir);
  for (auto _ : state) {
    const Session loaded = load_session(dir);
    benchmark::DoNotOptimize(loaded.iterations.back().record.joint_samples(0).angle_rad(10));
  }
}
BENCHMARK(BM_LoadPaperSession)->Unit(benchmark::kMillisecond)->UseRealTime();

void BM_LoadPaperManifest(benchmark::State& state) {
  const fs::path dir = scratch_dir() / "load";
  if (!fs::exists(dir)) save_session(paper_session(), dir);
  for (auto _ : state) benchmark::DoNotOptimize(load_manifest(dir).iterations.size());
}
BENCHMARK(BM_LoadPaperManifest)->Unit(benchmark::kMillisecond)->UseRealTime();

/// The autosave after one iteration: its two files and the manifest, with every fsync.
void BM_AutosavePaperIteration(benchmark::State& state) {
  const Session& session = paper_session();
  SessionManifest header = session.manifest;
  header.iterations.clear();
  header.resume.reset();
  static int runs = 0;  // the library calls this function more than once
  SessionWriter writer =
      SessionWriter::create(scratch_dir(), "autosave-" + std::to_string(runs++), header, session.trajectory, "bench");
  int index = 0;
  for (auto _ : state) {
    const std::size_t source = static_cast<std::size_t>(index) % session.iterations.size();
    IterationSummary summary = session.manifest.iterations[source].summary;
    summary.iteration = index++;
    writer.save_iteration(session.iterations[source].record, summary, session.iterations[source].next_corrections_bar(),
                          *session.manifest.resume);
  }
}
BENCHMARK(BM_AutosavePaperIteration)->Unit(benchmark::kMillisecond)->UseRealTime();

/// The CPU part of saving: formatting every iteration's two CSV files, no I/O.
void BM_FormatPaperSession(benchmark::State& state) {
  const Session& session = paper_session();
  for (auto _ : state) {
    std::size_t bytes = 0;
    for (const IterationData& data : session.iterations) {
      bytes += format_samples_csv(data.record, data.next_corrections_bar()).size();
      bytes += format_telemetry_csv(data.record).size();
    }
    benchmark::DoNotOptimize(bytes);
    state.counters["MB"] = static_cast<double>(bytes) / 1e6;
  }
}
BENCHMARK(BM_FormatPaperSession)->Unit(benchmark::kMillisecond)->UseRealTime();

void BM_ExportPaperSessionMat(benchmark::State& state) {
  const Session& session = paper_session();
  for (auto _ : state) export_session_mat(session, scratch_dir() / "paper.mat");
}
BENCHMARK(BM_ExportPaperSessionMat)->Unit(benchmark::kMillisecond)->UseRealTime();

void BM_ExportPaperSessionCsv(benchmark::State& state) {
  const Session& session = paper_session();
  for (auto _ : state) export_session_csv(session, scratch_dir() / "paper.csv");
}
BENCHMARK(BM_ExportPaperSessionCsv)->Unit(benchmark::kMillisecond)->UseRealTime();

}  // namespace
}  // namespace bellows

int main(int argc, char** argv) {
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  std::error_code error;
  std::filesystem::remove_all(bellows::scratch_dir(), error);
  return 0;
}
