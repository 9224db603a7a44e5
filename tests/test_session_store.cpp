// Sessions saved and loaded: every field and sample survives; the writer's autosave; locking;
// listing and naming. Damaged sessions: test_session_damage.cpp.
#include <sys/wait.h>
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <cmath>
#include <functional>
#include <limits>
#include <thread>
#include <vector>

#include <gtest/gtest.h>

#include <algorithm>

#include "engine/base/errors.hpp"
#include "session_test_support.hpp"
#include "sessions/manifest_json.hpp"
#include "sessions/session_layout.hpp"
#include "sessions/session_lock.hpp"
#include "sessions/session_store.hpp"
#include "sessions/session_writer.hpp"
#include "tests/test_support.hpp"

namespace bellows {
namespace {

using testing::TempDir;
namespace fs = std::filesystem;

using testing::error_of;

/// Angles pass through degrees: bit for bit where a decimal reads back exactly, else within an ulp.
void expect_same_angles(const Eigen::VectorXd& loaded, const Eigen::VectorXd& saved, const char* what) {
  ASSERT_EQ(loaded.size(), saved.size()) << what;
  for (Eigen::Index k = 0; k < saved.size(); ++k) {
    EXPECT_NEAR(loaded(k), saved(k), 2.5e-16 * std::abs(saved(k))) << what << " at " << k;
  }
}

void expect_same(const Eigen::VectorXd& loaded, const Eigen::VectorXd& saved, const char* what) {
  ASSERT_EQ(loaded.size(), saved.size()) << what;
  for (Eigen::Index k = 0; k < saved.size(); ++k) EXPECT_EQ(loaded(k), saved(k)) << what << " at " << k;
}

void expect_same_times(const Eigen::VectorXd& loaded, const Eigen::VectorXd& saved, const char* what) {
  ASSERT_EQ(loaded.size(), saved.size()) << what;
  for (Eigen::Index k = 0; k < saved.size(); ++k) EXPECT_NEAR(loaded(k), saved(k), 1e-9) << what << " at " << k;
}

void expect_same_controller(const ControlCore::State& state_a, const ControlCore::State& state_b) {
  ASSERT_EQ(state_a.joint_count, state_b.joint_count);
  for (int j = 0; j < state_a.joint_count; ++j) {
    const ControlCore::JointState& a = state_a.joints[static_cast<std::size_t>(j)];
    const ControlCore::JointState& b = state_b.joints[static_cast<std::size_t>(j)];
    EXPECT_EQ(a.pid.integral_s, b.pid.integral_s);
    EXPECT_EQ(a.pid.previous_output, b.pid.previous_output);
    EXPECT_EQ(a.pid.has_previous, b.pid.has_previous);
    for (const auto& [x, y] : {std::pair{&a.pressure_a, &b.pressure_a}, std::pair{&a.pressure_b, &b.pressure_b}}) {
      EXPECT_EQ(x->history_bar, y->history_bar);
      EXPECT_EQ(x->count, y->count);
      EXPECT_EQ(x->next, y->next);
      EXPECT_EQ(x->sum_bar, y->sum_bar);
    }
    EXPECT_EQ(a.setpoints.a_bar, b.setpoints.a_bar);
    EXPECT_EQ(a.setpoints.b_bar, b.setpoints.b_bar);
    EXPECT_EQ(a.setpoints.saturation_sign, b.setpoints.saturation_sign);
    EXPECT_EQ(a.hold_rad, b.hold_rad);
    EXPECT_EQ(a.desired_rad, b.desired_rad);
    EXPECT_EQ(a.u_total_bar, b.u_total_bar);
  }
  EXPECT_EQ(state_a.tick_in_sample, state_b.tick_in_sample);
}

void expect_same_configuration(const Configuration& a, const Configuration& b) {
  Configuration x = a, y = b;
  for (const ParameterBinding& binding : parameter_bindings()) {
    const std::string key = binding.section + "." + binding.key;
    if (binding.text) EXPECT_EQ(*binding.text(x), *binding.text(y)) << key;
    else if (binding.integer) EXPECT_EQ(*binding.integer(x), *binding.integer(y)) << key;
    else EXPECT_EQ(*binding.real(x), *binding.real(y)) << key;
  }
  EXPECT_EQ(x.controller.gas.ambient_bar, y.controller.gas.ambient_bar);
  EXPECT_EQ(x.controller.gas.temperature_K, y.controller.gas.temperature_K);
}

void expect_same_session(const Session& loaded, const Session& saved) {
  const SessionManifest& a = loaded.manifest;
  const SessionManifest& b = saved.manifest;
  EXPECT_EQ(a.schema_version, b.schema_version);
  EXPECT_EQ(a.program_version, b.program_version);
  EXPECT_EQ(a.name, b.name);
  EXPECT_EQ(a.device, b.device);
  EXPECT_EQ(a.device_info, b.device_info);
  EXPECT_EQ(a.started_utc, b.started_utc);
  expect_same_configuration(a.configuration, b.configuration);
  EXPECT_EQ(a.trajectory_name, b.trajectory_name);
  EXPECT_EQ(a.trajectory_samples, b.trajectory_samples);
  ASSERT_EQ(a.iterations.size(), b.iterations.size());
  for (std::size_t i = 0; i < a.iterations.size(); ++i) {
    const IterationSummary& x = a.iterations[i].summary;
    const IterationSummary& y = b.iterations[i].summary;
    EXPECT_EQ(x.iteration, y.iteration);
    EXPECT_EQ(x.rms_deg, y.rms_deg);
    EXPECT_EQ(x.max_abs_error_deg, y.max_abs_error_deg);
    EXPECT_EQ(x.max_abs_correction_bar, y.max_abs_correction_bar);
    EXPECT_EQ(x.saturated_samples, y.saturated_samples);
    EXPECT_EQ(a.iterations[i].completed_utc, b.iterations[i].completed_utc);
  }
  ASSERT_EQ(a.events.size(), b.events.size());
  for (std::size_t e = 0; e < a.events.size(); ++e) {
    EXPECT_EQ(a.events[e].time_utc, b.events[e].time_utc);
    EXPECT_EQ(a.events[e].iteration, b.events[e].iteration);
    EXPECT_EQ(a.events[e].kind, b.events[e].kind);
    EXPECT_EQ(a.events[e].message, b.events[e].message);
  }
  ASSERT_EQ(a.resume.has_value(), b.resume.has_value());
  if (a.resume) {
    ASSERT_EQ(a.resume->exact(), b.resume->exact());
    if (a.resume->exact()) expect_same_controller(*a.resume->controller, *b.resume->controller);
    EXPECT_EQ(a.resume->device, b.resume->device);
    EXPECT_EQ(a.resume->clock_ticks, b.resume->clock_ticks);
  }
  EXPECT_EQ(loaded.trajectory.name, saved.trajectory.name);
  EXPECT_EQ(loaded.trajectory.sample_time_s, saved.trajectory.sample_time_s);
  expect_same(loaded.trajectory.joint(0), saved.trajectory.joint(0), "trajectory");  // from degrees: exact

  ASSERT_EQ(loaded.iterations.size(), saved.iterations.size());
  for (std::size_t i = 0; i < loaded.iterations.size(); ++i) {
    const TrialRecord& x = loaded.iterations[i].record;
    const TrialRecord& y = saved.iterations[i].record;
    EXPECT_EQ(x.learning_samples, y.learning_samples);
    EXPECT_TRUE(x.complete);
    expect_same_times(x.sample_time_s, y.sample_time_s, "samples time");
    expect_same_angles(x.joint_samples(0).setpoint_rad, y.joint_samples(0).setpoint_rad, "set point");
    expect_same_angles(x.joint_samples(0).angle_rad, y.joint_samples(0).angle_rad, "angle");
    expect_same_angles(x.joint_samples(0).error_rad, y.joint_samples(0).error_rad, "error");
    expect_same(x.joint_samples(0).u_pid_bar, y.joint_samples(0).u_pid_bar, "u_pid");
    expect_same(x.joint_samples(0).u_ilc_bar, y.joint_samples(0).u_ilc_bar, "u_ilc");
    expect_same(x.joint_samples(0).u_total_bar, y.joint_samples(0).u_total_bar, "u_tot");
    expect_same(x.joint_samples(0).pressure_a_bar, y.joint_samples(0).pressure_a_bar, "pressure A");
    expect_same(x.joint_samples(0).pressure_b_bar, y.joint_samples(0).pressure_b_bar, "pressure B");
    expect_same(x.joint_samples(0).setpoint_a_bar, y.joint_samples(0).setpoint_a_bar, "set point A");
    expect_same(x.joint_samples(0).setpoint_b_bar, y.joint_samples(0).setpoint_b_bar, "set point B");
    expect_same(loaded.iterations[i].next_corrections_bar(), saved.iterations[i].next_corrections_bar(),
                "next correction");
    expect_same_times(x.tick_time_s, y.tick_time_s, "ticks time");
    expect_same_angles(x.joint_ticks(0).angle_rad, y.joint_ticks(0).angle_rad, "ticks angle");
    expect_same(x.joint_ticks(0).pressure_a_bar, y.joint_ticks(0).pressure_a_bar, "ticks pressure A");
    expect_same(x.joint_ticks(0).pressure_b_bar, y.joint_ticks(0).pressure_b_bar, "ticks pressure B");
    expect_same(x.supply_bar, y.supply_bar, "ticks supply");
    expect_same(x.joint_ticks(0).setpoint_a_bar, y.joint_ticks(0).setpoint_a_bar, "ticks set point A");
    expect_same(x.joint_ticks(0).setpoint_b_bar, y.joint_ticks(0).setpoint_b_bar, "ticks set point B");
    expect_same(x.joint_ticks(0).inlet_a, y.joint_ticks(0).inlet_a, "inlet A");
    expect_same(x.joint_ticks(0).outlet_a, y.joint_ticks(0).outlet_a, "outlet A");
    expect_same(x.joint_ticks(0).inlet_b, y.joint_ticks(0).inlet_b, "inlet B");
    expect_same(x.joint_ticks(0).outlet_b, y.joint_ticks(0).outlet_b, "outlet B");
    EXPECT_NEAR(x.rms_error_deg(), y.rms_error_deg(), 1e-12);
  }
}

TEST(SessionStore, SaveAndLoadGiveBackEveryFieldAndSample) {
  TempDir dir;
  const Session saved = testing::simulate_session(4);
  save_session(saved, dir / "s");
  const Session loaded = load_session(dir / "s");
  EXPECT_EQ(loaded.directory, dir / "s");
  expect_same_session(loaded, saved);
  // Saving what was loaded writes the same files again.
  save_session(loaded, dir / "copy");
  for (const std::string& file : std::vector<std::string>{
           session_layout::samples_file(2), session_layout::telemetry_file(3), session_layout::kTrajectory}) {
    EXPECT_EQ(testing::read_text(dir / "copy" / file), testing::read_text(dir / "s" / file)) << file;
  }
}

TEST(SessionStore, ManifestRoundTripsThroughJson) {
  Session saved = testing::simulate_session(2);
  saved.manifest.events.push_back({"2024-01-01T00:00:00.000Z", 1, "note", "quotes \" and\nnewlines, ünïcödé"});
  const std::string text = format_manifest(saved.manifest);
  const SessionManifest loaded = parse_manifest(text, "m");
  EXPECT_EQ(format_manifest(loaded), text);
  EXPECT_EQ(loaded.events.back().message, "quotes \" and\nnewlines, ünïcödé");
}

TEST(SessionStore, AnEventKeepsItsEngineTimeAndOneWithoutNoneIsWrittenForIt) {
  Session saved = testing::simulate_session(1);
  saved.manifest.events.push_back({"2024-01-01T00:00:00.000Z", 0, "operator", "arm", 12.345678901});
  saved.manifest.events.push_back({"2024-01-01T00:00:01.000Z", 0, "note", "no engine time"});
  const std::string text = format_manifest(saved.manifest);
  const SessionManifest loaded = parse_manifest(text, "m");
  ASSERT_GE(loaded.events.size(), 2u);
  EXPECT_EQ(loaded.events[loaded.events.size() - 2].engine_time_s, 12.345678901);  // to the last bit
  EXPECT_LT(loaded.events.back().engine_time_s, 0.0);
  const nlohmann::json json = nlohmann::json::parse(text);
  EXPECT_FALSE(json["events"].back().contains("engine_time_s"));  // older readers' and sessions' shape
  nlohmann::json hostile = json;
  hostile["events"].back()["engine_time_s"] = -3.0;
  EXPECT_THROW(parse_manifest(hostile.dump(), "m"), InputError);
}

TEST(SessionStore, AManifestWrittenPieceByPieceIsTheSameText) {
  // A writer serializes only what was added since its last write: the text must be what a whole
  // serialization gives, through appends, a change of the newest entry and a list that shrank.
  const Session simulated = testing::simulate_session(6);
  SessionManifest grown = simulated.manifest;
  grown.iterations.clear();
  grown.events.clear();
  ManifestTextCache cache;
  EXPECT_EQ(format_manifest(grown, cache), format_manifest(grown));
  for (std::size_t i = 0; i < simulated.manifest.iterations.size(); ++i) {
    grown.iterations.push_back(simulated.manifest.iterations[i]);
    grown.events.push_back({"2024-05-01T12:00:00.000Z", static_cast<int>(i), "note", "line\nwith \"quotes\" and \\"});
    ASSERT_EQ(format_manifest(grown, cache), format_manifest(grown)) << "after iteration " << i;
  }
  grown.iterations.back().samples_sha256 = std::string(64, 'a');  // the newest entry may still change
  EXPECT_EQ(format_manifest(grown, cache), format_manifest(grown));
  grown.iterations.resize(2);
  grown.events.clear();
  EXPECT_EQ(format_manifest(grown, cache), format_manifest(grown));
  EXPECT_EQ(parse_manifest(format_manifest(grown, cache), "m").iterations.size(), 2u);
}

TEST(SessionStore, ConfigurationOtherThanTheDefaultsSurvives) {
  Session saved = testing::simulate_session(1);
  saved.manifest.configuration.controller.k_p = 0.45;
  saved.manifest.configuration.controller.filter_samples = 6;
  saved.manifest.configuration.ilc.w = 3e-5;
  saved.manifest.configuration.plant.gas.temperature_K = 300.0;
  saved.manifest.configuration.controller.gas.temperature_K = 300.0;
  const SessionManifest loaded = parse_manifest(format_manifest(saved.manifest), "m");
  expect_same_configuration(loaded.configuration, saved.manifest.configuration);
}

TEST(SessionStore, AnEmptySessionLoads) {
  TempDir dir;
  Session saved = testing::simulate_session(0);
  save_session(saved, dir / "empty");
  const Session loaded = load_session(dir / "empty");
  EXPECT_TRUE(loaded.iterations.empty());
  EXPECT_FALSE(loaded.manifest.resume.has_value());
}

TEST(SessionStore, SavingOverAnExistingSessionIsRefused) {
  TempDir dir;
  const Session saved = testing::simulate_session(1);
  save_session(saved, dir / "s");
  EXPECT_NE(error_of([&] { save_session(saved, dir / "s"); }).find("exists already"), std::string::npos);
  EXPECT_EQ(load_session(dir / "s").iterations.size(), 1u);
}

TEST(SessionWriter, AutosavesEveryIterationAndEvent) {
  TempDir dir;
  const Session simulated = testing::simulate_session(3);
  SessionManifest header = simulated.manifest;
  header.iterations.clear();
  header.resume.reset();
  SessionWriter writer = SessionWriter::create(dir.path(), "w", header, simulated.trajectory, "test");
  EXPECT_EQ(writer.directory(), dir / "w");
  EXPECT_TRUE(load_session(writer.directory()).iterations.empty());  // loadable from the start
  for (std::size_t i = 0; i < simulated.iterations.size(); ++i) {
    writer.save_iteration(simulated.iterations[i].record, simulated.manifest.iterations[i].summary,
                          simulated.iterations[i].next_corrections_bar(), *simulated.manifest.resume);
    EXPECT_EQ(load_session(writer.directory()).iterations.size(), i + 1);
  }
  writer.record_event("fault", "supply pressure lost");
  const Session loaded = load_session(writer.directory());
  ASSERT_EQ(loaded.iterations.size(), 3u);
  EXPECT_EQ(loaded.manifest.events.back().kind, "fault");
  EXPECT_EQ(loaded.manifest.events.back().iteration, 3);
  for (std::size_t i = 0; i < 3; ++i) {
    expect_same(loaded.iterations[i].next_corrections_bar(), simulated.iterations[i].next_corrections_bar(),
                "correction");
    EXPECT_EQ(loaded.manifest.iterations[i].summary.rms_deg, simulated.manifest.iterations[i].summary.rms_deg);
  }
  // Out of order is a programming error, not bad input.
  EXPECT_THROW(writer.save_iteration(simulated.iterations[0].record, simulated.manifest.iterations[0].summary,
                                     simulated.iterations[0].next_corrections_bar(), *simulated.manifest.resume),
               std::invalid_argument);
}

// A reader takes no lock: while the console updates the learned correction (a new revision of the
// last samples file, the manifest naming it, the old revision removed) a load that read the old
// manifest would find its file gone. It reads again from the new manifest instead of failing.
TEST(SessionReaders, ALoadRacingACorrectionUpdateReadsTheSessionAgain) {
  TempDir dir;
  const Session simulated = testing::simulate_session(2);
  save_session(simulated, dir / "s");
  Session opened;
  SessionWriter writer = SessionWriter::open(dir / "s", "test", opened);
  const TrialRecord& last = simulated.iterations.back().record;
  const Eigen::VectorXd correction = simulated.iterations.back().next_corrections_bar().col(0);
  // The console commits a new correction once a trial, seconds apart; a load takes milliseconds. The
  // writer here commits far more often, yet a load's time apart (twice what one took: a sanitizer
  // build's slow loads included), so that a load overlaps a commit about half the time: the race,
  // not a writer that never lets a reader finish.
  const auto started = std::chrono::steady_clock::now();
  EXPECT_EQ(load_session(dir / "s").iterations.size(), 2u);
  const auto load_time = std::chrono::steady_clock::now() - started;
  constexpr int kCommits = 100;
  std::atomic<bool> done{false};
  std::thread updates([&] {
    for (int i = 0; i < kCommits; ++i) {
      const Eigen::VectorXd next = correction * (1.0 + 1e-3 * (i % 7));
      writer.update_next_correction(last, next);
      std::this_thread::sleep_for(2 * load_time);
    }
    done = true;
  });
  int loads = 0;
  std::vector<std::string> failures;
  while (!done || loads == 0) {
    try {
      const Session loaded = load_session(dir / "s");
      EXPECT_EQ(loaded.iterations.size(), 2u);
    } catch (const InputError& error) {
      failures.emplace_back(error.what());
    }
    ++loads;
  }
  updates.join();
  EXPECT_TRUE(failures.empty()) << failures.size() << " of " << loads << " loads failed, e.g. " << failures.front();
  EXPECT_EQ(load_session(dir / "s").manifest.iterations.back().samples_revision, kCommits);
}

TEST(SessionWriter, ReopeningClearsWhatAnInterruptedWriteLeftBehind) {
  TempDir dir;
  save_session(testing::simulate_session(2), dir / "s");
  const fs::path iterations = dir / "s" / session_layout::kIterations;
  fs::copy_file(dir / "s" / session_layout::samples_file(1), dir / "s" / session_layout::samples_file(2));  // unlisted
  testing::write_text(iterations / ".telemetry_0002.csv.tmp-4242", "time_s,ang");
  testing::write_text(dir / "s" / ".manifest.json.tmp-4242", "{");
  Session loaded;
  SessionWriter writer = SessionWriter::open(dir / "s", "test", loaded);
  EXPECT_EQ(loaded.iterations.size(), 2u);
  EXPECT_FALSE(fs::exists(dir / "s" / session_layout::samples_file(2)));
  EXPECT_FALSE(fs::exists(iterations / ".telemetry_0002.csv.tmp-4242"));
  EXPECT_FALSE(fs::exists(dir / "s" / ".manifest.json.tmp-4242"));
  EXPECT_TRUE(fs::exists(dir / "s" / session_layout::samples_file(1)));
}

// A run killed while it wrote its LCM log into the session (run --lcm-log) left the log as a hidden
// temporary: not a save's leftover but the record of what the run sent, kept under its own name (the
// next free one when that is taken) instead of removed, and not reported as a dropped save.
TEST(SessionWriter, ReopeningKeepsTheLcmLogOfAKilledRun) {
  TempDir dir;
  save_session(testing::simulate_session(2), dir / "s");
  testing::write_text(dir / "s" / ".telemetry.lcmlog.tmp-4242-00ff", "events up to the kill");
  testing::write_text(dir / "s" / "telemetry-2.lcmlog", "a log a resume committed");
  testing::write_text(dir / "s" / ".telemetry-2.lcmlog.tmp-4243-00ff", "a resumed run's events up to its kill");
  Session loaded;
  {
    SessionWriter writer = SessionWriter::open(dir / "s", "test", loaded);
    EXPECT_EQ(loaded.dropped, "");
    std::vector<std::string> kept = writer.kept_logs();
    std::sort(kept.begin(), kept.end());
    ASSERT_EQ(kept.size(), 2u);
    EXPECT_EQ(kept[0], "telemetry-3.lcmlog");
    EXPECT_EQ(kept[1], "telemetry.lcmlog");
  }
  EXPECT_EQ(testing::read_text(dir / "s" / "telemetry.lcmlog"), "events up to the kill");
  EXPECT_EQ(testing::read_text(dir / "s" / "telemetry-2.lcmlog"), "a log a resume committed");
  EXPECT_EQ(testing::read_text(dir / "s" / "telemetry-3.lcmlog"), "a resumed run's events up to its kill");
  EXPECT_FALSE(fs::exists(dir / "s" / ".telemetry.lcmlog.tmp-4242-00ff"));
  EXPECT_EQ(load_session(dir / "s").iterations.size(), 2u);  // the session loads with the logs beside it
}

TEST(SessionWriter, NamesSessionsByStartTimeAndTrajectory) {
  TempDir dir;
  const Session simulated = testing::simulate_session(0);
  SessionWriter first = SessionWriter::create(dir.path(), "", simulated.manifest, simulated.trajectory, "test");
  SessionWriter second = SessionWriter::create(dir.path(), "", simulated.manifest, simulated.trajectory, "test");
  const std::string name = first.directory().filename().string();
  EXPECT_EQ(name.size(), std::string("2024-05-01_14-03-07_short").size()) << name;
  EXPECT_EQ(name.substr(name.size() - 6), "_short");
  EXPECT_NE(first.directory(), second.directory());
  EXPECT_EQ(first.manifest().name, name);
}

TEST(SessionWriter, RunsStartedTogetherGetSessionsOfTheirOwn) {
  // Several runs in the same second look for a free name before any of them has created it: each
  // must still get a session of its own, never "in use by" another (a CI run of tests met this).
  TempDir dir;
  const Session simulated = testing::simulate_session(0);
  constexpr int kRuns = 6;
  std::vector<std::string> names(kRuns), errors(kRuns);
  std::atomic<int> waiting{kRuns};
  std::vector<std::thread> runs;
  for (int i = 0; i < kRuns; ++i) {
    runs.emplace_back([&, i] {
      waiting.fetch_sub(1);
      while (waiting.load() > 0) std::this_thread::yield();
      try {
        SessionWriter writer = SessionWriter::create(dir.path(), "", simulated.manifest, simulated.trajectory, "test");
        names[i] = writer.directory().filename().string();
      } catch (const std::exception& error) {
        errors[i] = error.what();
      }
    });
  }
  for (auto& run : runs) run.join();
  for (int i = 0; i < kRuns; ++i) EXPECT_EQ(errors[i], "") << "run " << i;
  std::sort(names.begin(), names.end());
  EXPECT_EQ(std::unique(names.begin(), names.end()), names.end());
}

TEST(SessionWriter, RefusesNonFiniteValuesAndKeepsWhatWasSaved) {
  TempDir dir;
  Session simulated = testing::simulate_session(2);
  SessionManifest header = simulated.manifest;
  header.iterations.clear();
  header.resume.reset();
  SessionWriter writer = SessionWriter::create(dir.path(), "n", header, simulated.trajectory, "test");
  writer.save_iteration(simulated.iterations[0].record, simulated.manifest.iterations[0].summary,
                        simulated.iterations[0].next_corrections_bar(), *simulated.manifest.resume);
  simulated.iterations[1].record.joint_samples(0).angle_rad(3) = std::numeric_limits<double>::quiet_NaN();
  EXPECT_NE(error_of([&] {
              writer.save_iteration(simulated.iterations[1].record, simulated.manifest.iterations[1].summary,
                                    simulated.iterations[1].next_corrections_bar(), *simulated.manifest.resume);
            }).find("iteration 1: angle at index 3 is not a finite number"),
            std::string::npos);
  EXPECT_EQ(load_session(writer.directory()).iterations.size(), 1u);
}

TEST(SessionLock, ASecondWriterIsRefusedWithTheFirstNamed) {
  TempDir dir;
  const Session simulated = testing::simulate_session(1);
  save_session(simulated, dir / "s");
  Session loaded;
  SessionWriter first = SessionWriter::open(dir / "s", "first writer", loaded);
  const std::string refusal = error_of([&] {
    Session again;
    SessionWriter::open(dir / "s", "second writer", again);
  });
  EXPECT_NE(refusal.find("is in use by first writer (pid " + std::to_string(::getpid())), std::string::npos) << refusal;
  EXPECT_EQ(SessionLock::holder(dir / "s").value_or("").rfind("first writer", 0), 0u);
}

TEST(SessionLock, IsReleasedWhenTheHolderDiesEvenByKill) {
  TempDir dir;
  save_session(testing::simulate_session(1), dir / "s");
  int ready[2];
  ASSERT_EQ(::pipe(ready), 0);
  const pid_t child = ::fork();
  if (child == 0) {
    SessionLock lock(dir / "s", "child");
    ::write(ready[1], "x", 1);
    ::pause();
    ::_exit(0);
  }
  char byte;
  ASSERT_EQ(::read(ready[0], &byte, 1), 1);
  EXPECT_NE(
      error_of([&] { SessionLock lock(dir / "s", "parent"); }).find("is in use by child (pid " + std::to_string(child)),
      std::string::npos);
  ::kill(child, SIGKILL);
  ::waitpid(child, nullptr, 0);
  EXPECT_NO_THROW(SessionLock(dir / "s", "parent"));
  EXPECT_FALSE(SessionLock::holder(dir / "s").has_value());
}

TEST(SessionStore, ListsSessionsAndFlagsBadOnes) {
  TempDir dir;
  save_session(testing::simulate_session(2, "one"), dir / "one");
  save_session(testing::simulate_session(1, "two"), dir / "two");
  fs::create_directories(dir / "broken");
  fs::create_directories(dir / ".two.creating-123");  // a crashed creation: hidden, skipped
  const std::vector<SessionListing> listings = list_sessions(dir.path());
  ASSERT_EQ(listings.size(), 3u);
  int good = 0;
  for (const SessionListing& listing : listings) {
    if (listing.directory.filename() == "broken") {
      EXPECT_NE(listing.error.find("manifest.json is missing"), std::string::npos);
    } else {
      EXPECT_TRUE(listing.error.empty()) << listing.error;
      ++good;
    }
  }
  EXPECT_EQ(good, 2);
  EXPECT_TRUE(list_sessions(dir / "nowhere").empty());
  EXPECT_GT(best_rms_deg(listings.back().manifest), 0.0);
}

TEST(SessionStore, DefaultDataDirFollowsXdg) {
  const char* old_xdg = std::getenv("XDG_DATA_HOME");
  const std::string saved_xdg = old_xdg ? old_xdg : "";
  ::setenv("XDG_DATA_HOME", "/data/xdg", 1);
  EXPECT_EQ(default_data_dir(), fs::path("/data/xdg/bellows/sessions"));
  ::setenv("XDG_DATA_HOME", "relative/ignored", 1);
  const char* home = std::getenv("HOME");
  if (home != nullptr && home[0] == '/') {
    EXPECT_EQ(default_data_dir(), fs::path(home) / ".local/share/bellows/sessions");
  }
  if (old_xdg) {
    ::setenv("XDG_DATA_HOME", saved_xdg.c_str(), 1);
  } else {
    ::unsetenv("XDG_DATA_HOME");
  }
}

TEST(SessionStore, SessionNamesMustBePlainDirectoryNames) {
  EXPECT_NO_THROW(validate_session_name("run-3 paper"));
  for (const std::string& bad : std::vector<std::string>{"", "a/b", ".hidden", "tab\there", std::string(201, 'x')}) {
    EXPECT_THROW(validate_session_name(bad), InputError) << bad;
  }
}

}  // namespace
}  // namespace bellows
