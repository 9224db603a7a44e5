// The console's save and open on the real session store: what the console saves reopens the same,
// later saves append, a session is one console's at a time, and bad sessions say why.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdlib>
#include <fstream>

#include "app/console_sessions.hpp"
#include "engine/base/errors.hpp"
#include "sessions/session_store.hpp"
#include "tests/console_fixture.hpp"
#include "tests/process_runner.hpp"
#include "ui/canvas.hpp"
#include "ui/render.hpp"

namespace bellows {
namespace {

using testing::ConsoleFixture;

/// Points the data directory ($XDG_DATA_HOME) at a fresh temporary directory for one test.
class UiSessions : public ::testing::Test {
 protected:
  void SetUp() override {
    data_home_ = testing::make_temp_dir("bellows-ui-sessions");
    const char* previous = std::getenv("XDG_DATA_HOME");
    if (previous != nullptr) previous_ = previous;
    had_previous_ = previous != nullptr;
    setenv("XDG_DATA_HOME", data_home_.c_str(), 1);
  }
  void TearDown() override {
    if (had_previous_) setenv("XDG_DATA_HOME", previous_.c_str(), 1);
    else unsetenv("XDG_DATA_HOME");
    std::filesystem::remove_all(data_home_);
  }
  std::filesystem::path sessions_dir() const { return data_home_ / "bellows" / "sessions"; }

  std::filesystem::path data_home_;
  std::string previous_;
  bool had_previous_ = false;
};

/// The console saves as it goes: waits until everything done so far is on disk.
void save_and_wait(ConsoleFixture& f) {
  ASSERT_TRUE(f.pump_until([&] { return f.console->saves_settled(); }));
  ASSERT_FALSE(f.state().experiment.unsaved()) << f.state().status;
}

/// A console with `config` runs one trial and saves it as a session of the data directory; its location
/// ("" after a failed assertion).
std::string record_one_trial(const Configuration& config) {
  StoreSessionGateway gateway("sim");
  ConsoleFixture f(config, 3, &gateway);
  f.arm_valves();
  f.key('r');
  EXPECT_TRUE(f.pump_until([&] { return f.idle(); }));
  save_and_wait(f);
  return f.state().experiment.session_location;
}

/// `o` in a fresh console: the browser lists the data directory's one session.
void list_sessions_in_browser(ConsoleFixture& f) {
  ASSERT_TRUE(f.pump_until([&] { return f.state().law_ready; }));
  f.key('o');
  ASSERT_TRUE(f.pump_until([&] { return !f.state().browser.loading; }));
  ASSERT_EQ(f.state().browser.sessions.size(), 1u);
}

TEST_F(UiSessions, WhatTheConsoleSavesReopensTheSame) {
  StoreSessionGateway gateway("sim");
  ASSERT_TRUE(gateway.available()) << gateway.unavailable_reason();
  ConsoleFixture f(Configuration{}, 3, &gateway);
  f.arm_valves();
  f.run_batch(2);  // iterations 0..2 (docs/iterations.md)
  save_and_wait(f);
  const ui::Experiment& saved = f.state().experiment;
  ASSERT_FALSE(saved.session_location.empty());
  EXPECT_EQ(std::filesystem::path(saved.session_location).parent_path(), sessions_dir());
  EXPECT_EQ(saved.saved_trials, 3);

  // The session is the console's while it holds it.
  StoreSessionGateway other("sim");
  EXPECT_THROW(other.open(saved.session_location), InputError);

  const std::string location = saved.session_location;
  std::vector<std::pair<std::string, double>> engine_times;  // what the log showed, with engine times
  for (const ui::LogEntry& entry : f.state().log.entries()) {
    if (entry.engine_time_s >= 0.0 && !entry.routine && entry.source != ui::LogSource::kLearner) {
      engine_times.emplace_back(entry.text, entry.engine_time_s);
    }
  }
  f.console.reset();
  const ui::SessionSnapshot copy = gateway.open(location);  // the gateway that holds it may reopen it
  // Every saved line keeps its engine time, those of the first save (the session's creation) too;
  // later saves write it to the millisecond.
  ASSERT_FALSE(engine_times.empty());
  for (const auto& [text, engine_time_s] : engine_times) {
    const std::string& saved_text = text;  // clang 14 cannot capture a structured binding
    const auto reopened = std::find_if(copy.events.begin(), copy.events.end(),
                                       [&](const ui::LogEntry& e) { return e.text == saved_text; });
    ASSERT_NE(reopened, copy.events.end()) << text;
    EXPECT_NEAR(reopened->engine_time_s, engine_time_s, 0.0005) << text;
  }
  const ui::Experiment& e = copy.experiment;
  ASSERT_EQ(e.trials.size(), 3u);
  EXPECT_EQ(e.trajectory->name, "paper");
  for (int i = 0; i < 3; ++i) {
    const ui::Trial& t = e.trials[static_cast<std::size_t>(i)];
    EXPECT_EQ(t.iteration, i);
    EXPECT_GT(t.summary.rms_deg, 0.0);
    EXPECT_EQ(t.record.learning_samples, 400);
  }
  EXPECT_LT(e.trials[2].summary.rms_deg, e.trials[0].summary.rms_deg);
  EXPECT_TRUE(e.trials[0].correction_bar.isZero());
  EXPECT_GT(e.trials[2].correction_bar.cwiseAbs().maxCoeff(), 0.01);
  // The last trial ran with the correction saved as "next": a step learns first.
  EXPECT_TRUE(e.next_tried);
  EXPECT_EQ(e.saved_trials, 3);
  bool armed_logged = false;
  for (const ui::LogEntry& entry : copy.events) armed_logged = armed_logged || entry.text == "SAFE -> ARMED (arm)";
  EXPECT_TRUE(armed_logged);
  EXPECT_EQ(copy.seed, 1u);
}

TEST_F(UiSessions, LaterSavesAppendIterationsSettingsAndLog) {
  StoreSessionGateway gateway("sim");
  ConsoleFixture f(Configuration{}, 3, &gateway);
  f.arm_valves();
  f.run_batch(1);  // iterations 0..1
  save_and_wait(f);
  const std::string location = f.state().experiment.session_location;
  f.key('w');
  f.key(ui::key::kDown);
  f.key(ui::key::kEnter);
  for (int i = 0; i < 3; ++i) f.key(ui::key::kBackspace);
  f.type("0.35");
  f.key(ui::key::kEnter);
  f.key('n');
  ASSERT_TRUE(f.pump_until([&] { return f.idle(); }));
  save_and_wait(f);
  EXPECT_EQ(f.state().experiment.session_location, location);  // the same session, grown
  f.console.reset();

  const Session loaded = load_session(location);
  ASSERT_EQ(loaded.manifest.iterations.size(), 3u);
  EXPECT_DOUBLE_EQ(loaded.manifest.configuration.controller.k_p, 0.35);
  bool change_logged = false;
  for (const SessionEvent& e : loaded.manifest.events) {
    change_logged = change_logged || e.message.find("k_p changed 0.3 -> 0.35") != std::string::npos;
  }
  EXPECT_TRUE(change_logged);
  // Each iteration's next correction is what the next one ran with: iteration 1 was saved with its
  // own, and rewritten with the learned one before iteration 2 started.
  const auto applied = [&](std::size_t i) {
    return Eigen::VectorXd(loaded.iterations[i].record.joint_samples(0).u_ilc_bar.head(400));
  };
  EXPECT_TRUE(loaded.iterations[0].next_corrections_bar().isApprox(applied(1)));
  EXPECT_TRUE(loaded.iterations[1].next_corrections_bar().isApprox(applied(2)));
  EXPECT_FALSE(applied(2).isApprox(applied(1)));
}

TEST_F(UiSessions, AFaultsBlackBoxIsSavedWithTheSessionAndReopened) {
  StoreSessionGateway gateway("sim");
  ConsoleFixture f(Configuration{}, 3, &gateway);
  f.arm_valves();
  f.run_batch(1);  // iterations 0..1
  f.key(' ');      // emergency stop before iteration 2
  ASSERT_TRUE(f.pump_until([&] { return !f.state().fault_view.black_box.empty(); }));
  ASSERT_EQ(f.state().experiment.faults.size(), 1u);
  save_and_wait(f);
  EXPECT_EQ(f.state().experiment.saved_faults, 1);
  const std::string location = f.state().experiment.session_location;
  const std::vector<TickRecord> shown = f.state().fault_view.black_box;
  f.console.reset();

  const Session loaded = load_session(location);
  ASSERT_EQ(loaded.manifest.black_boxes.size(), 1u);
  EXPECT_EQ(loaded.manifest.black_boxes[0].fault, "emergency-stop");
  EXPECT_EQ(loaded.manifest.black_boxes[0].iteration, 2);
  ASSERT_EQ(loaded.black_boxes[0].size(), shown.size());
  EXPECT_EQ(loaded.black_boxes[0].back().tick, shown.back().tick);
  EXPECT_EQ(loaded.black_boxes[0].back().state, EngineState::kFault);

  const ui::SessionSnapshot reopened = gateway.open(location);
  ASSERT_EQ(reopened.experiment.faults.size(), 1u);
  EXPECT_EQ(reopened.experiment.saved_faults, 1);
  EXPECT_EQ(reopened.experiment.faults[0].ticks.size(), shown.size());
}

TEST_F(UiSessions, OpeningThroughTheBrowserContinuesTheSession) {
  std::string location;
  {
    StoreSessionGateway gateway("sim");
    ConsoleFixture f(Configuration{}, 3, &gateway);
    f.arm_valves();
    f.run_batch(1);  // iterations 0..1
    save_and_wait(f);
    location = f.state().experiment.session_location;
  }
  StoreSessionGateway gateway("sim");
  ConsoleFixture f(Configuration{}, 3, &gateway);
  list_sessions_in_browser(f);
  const ui::SessionListing& l = f.state().browser.sessions[0];
  EXPECT_EQ(l.location, location);
  EXPECT_EQ(l.trajectory, "paper");
  EXPECT_EQ(l.iterations, 2);
  EXPECT_NEAR(l.best_rms_deg, 9.38, 0.3);
  EXPECT_EQ(l.date.size(), 16u) << l.date;
  EXPECT_EQ(l.device, "sim");  // from its manifest
  EXPECT_TRUE(l.refusal.empty()) << l.refusal;
  f.key(ui::key::kEnter);
  ASSERT_TRUE(f.pump_until([&] { return !f.state().learner_busy && f.state().law_ready; }));
  ASSERT_EQ(f.state().experiment.trials.size(), 2u);
  f.arm_valves();
  f.key('n');
  ASSERT_TRUE(f.pump_until([&] { return f.idle(); }));
  save_and_wait(f);
  EXPECT_EQ(f.state().experiment.session_location, location);
  f.console.reset();
  EXPECT_EQ(load_manifest(location).iterations.size(), 3u);
}

TEST_F(UiSessions, BadSessionsAreListedWithTheReasonAndNotOpened) {
  std::filesystem::create_directories(sessions_dir() / "broken");
  std::ofstream(sessions_dir() / "broken" / "manifest.json") << "{ not json";
  StoreSessionGateway gateway("sim");
  const auto listing = gateway.list();
  ASSERT_EQ(listing.size(), 1u);
  EXPECT_EQ(listing[0].name, "broken");
  EXPECT_FALSE(listing[0].error.empty());
  EXPECT_THROW(gateway.open((sessions_dir() / "broken").string()), InputError);
  EXPECT_THROW(gateway.open("no-such-session"), InputError);
}

TEST_F(UiSessions, ASessionFromAnotherDeviceIsRefused) {
  const std::string location = record_one_trial(Configuration{});
  ASSERT_FALSE(location.empty());
  StoreSessionGateway lcm("lcm");
  const auto listing = lcm.list();  // the browser knows before the operator picks it
  ASSERT_EQ(listing.size(), 1u);
  EXPECT_EQ(listing[0].device, "sim");
  EXPECT_EQ(ui::drive_refusal(listing[0], "lcm"), "recorded on the device 'sim'; this console drives 'lcm'");
  EXPECT_EQ(ui::drive_refusal(listing[0], "sim"), "");
  try {
    lcm.open(location);
    FAIL() << "opened a sim session on an lcm console";
  } catch (const InputError& error) {
    EXPECT_NE(std::string(error.what()).find("recorded on the device 'sim'"), std::string::npos) << error.what();
  }
}

// A session recorded at other ticks with the same sample time (0.01 s x 2 against the console's
// 0.005 s x 4) is not continued: its trials' telemetry would be of another shape than the session's,
// and every later show, export and resume would refuse the whole session.
TEST_F(UiSessions, ASessionOfOtherTicksIsNotOpened) {
  Configuration slow;
  slow.timing.tick_s = 0.01;
  slow.timing.ticks_per_sample = 2;
  const std::string location = record_one_trial(slow);
  ASSERT_FALSE(location.empty());
  StoreSessionGateway gateway("sim");
  ConsoleFixture f(Configuration{}, 3, &gateway);
  list_sessions_in_browser(f);
  f.key(ui::key::kEnter);
  ASSERT_TRUE(f.pump_until([&] { return f.logged("open failed"); }));
  EXPECT_TRUE(f.logged("recorded at [timing] tick_s = 0.01 s, ticks_per_sample = 2; this console runs 0.005 s, 4"));
  EXPECT_TRUE(f.state().experiment.trials.empty());
  EXPECT_NE(f.state().experiment.session_location, location);
  EXPECT_EQ(load_manifest(location).iterations.size(), 1u);
}

TEST_F(UiSessions, NamingRenamesTheSessionAndSavingGoesOnThere) {
  StoreSessionGateway gateway("sim", nlohmann::ordered_json::object(),
                              (data_home_ / "elsewhere").string());  // --data-dir
  ConsoleFixture f(Configuration{}, 3, &gateway);
  f.arm_valves();
  f.key('r');
  ASSERT_TRUE(f.pump_until([&] { return f.idle(); }));
  save_and_wait(f);
  EXPECT_EQ(std::filesystem::path(f.state().experiment.session_location).parent_path(), data_home_ / "elsewhere");
  f.key('s');
  ASSERT_EQ(f.state().dialog.kind, ui::DialogKind::kSessionName);
  for (int i = 0; i < 80; ++i) f.key(ui::key::kBackspace);
  f.type("morning-run");
  f.key(ui::key::kEnter);
  ASSERT_TRUE(f.pump_until([&] { return f.console->saves_settled(); }));
  EXPECT_EQ(f.state().experiment.session_location, (data_home_ / "elsewhere" / "morning-run").string())
      << f.state().status;
  f.key('r');
  ASSERT_TRUE(f.pump_until([&] { return f.idle(); }));
  save_and_wait(f);
  f.console.reset();
  EXPECT_EQ(load_manifest((data_home_ / "elsewhere" / "morning-run").string()).iterations.size(), 2u);
}

TEST(UiSessionDates, LocalDateOfUtc) {
  setenv("TZ", "UTC", 1);
  tzset();
  EXPECT_EQ(local_date_of("2024-05-01T14:03:07.123Z"), "2024-05-01 14:03");
  EXPECT_EQ(local_date_of("not a date"), "not a date");
  unsetenv("TZ");
  tzset();
}

TEST(UiSessionGateway, WithoutADataDirectoryItSaysWhy) {
  const char* xdg = std::getenv("XDG_DATA_HOME");
  const char* home = std::getenv("HOME");
  const std::string saved_xdg = xdg != nullptr ? xdg : "", saved_home = home != nullptr ? home : "";
  unsetenv("XDG_DATA_HOME");
  setenv("HOME", "relative/home", 1);
  StoreSessionGateway gateway("sim");
  EXPECT_FALSE(gateway.available());
  EXPECT_FALSE(gateway.unavailable_reason().empty());
  if (xdg != nullptr) setenv("XDG_DATA_HOME", saved_xdg.c_str(), 1);
  if (home != nullptr) setenv("HOME", saved_home.c_str(), 1);
  else unsetenv("HOME");
}

TEST_F(UiSessions, ASessionStartedFromATransferRecordsWhereItsFirstCorrectionCameFrom) {
  StoreSessionGateway gateway("sim");
  ConsoleFixture f(Configuration{}, 3, &gateway);
  f.arm_valves();
  f.run_batch(5);  // iterations 0..5: 6 trials
  save_and_wait(f);
  const std::string taught = f.state().experiment.session_location;
  f.key('t');
  f.key(ui::key::kDown);  // steps
  f.key(ui::key::kEnter);
  ASSERT_EQ(f.state().experiment.trajectory->name, "steps");
  ASSERT_TRUE(f.pump_until([&] { return f.state().status.find("T: start from what") != std::string::npos; }, 50.0))
      << f.state().status;
  f.key('T');
  ASSERT_NE(f.state().experiment.first_correction, nullptr);
  const double predicted = f.state().experiment.first_correction->result.predicted_rms_deg();
  f.key('r');
  ASSERT_TRUE(f.pump_until([&] { return f.idle(); }));
  save_and_wait(f);
  const std::string started = f.state().experiment.session_location;
  ASSERT_NE(started, taught);
  f.console.reset();

  const nlohmann::ordered_json first = load_manifest(started).first_correction;
  ASSERT_TRUE(first.is_object()) << first.dump();
  EXPECT_EQ(first["status"], "transferred");
  EXPECT_EQ(first["by"], "console");
  EXPECT_FALSE(first["method"].get<std::string>().empty());
  EXPECT_NEAR(first["prediction"]["rms_deg"].get<double>(), predicted, 1e-9);
  EXPECT_GT(first["prediction"]["feedback_only_rms_deg"].get<double>(), predicted);
  ASSERT_EQ(first["sources"].size(), 1u) << first.dump();
  EXPECT_EQ(first["sources"][0]["trajectory"], "paper");
  EXPECT_EQ(first["sources"][0]["directory"], taught);  // the taught trajectory's own session
  EXPECT_EQ(first["sources"][0]["trials"], 6);
  EXPECT_GT(first["sources"][0]["last_rms_deg"].get<double>(), 0.0);
  // The same keys as bellows run --transfer-from records.
  for (const char* key : {"sources", "method", "status", "reason", "prediction", "validation_ratio", "clamped_samples",
                          "max_abs_correction_bar"}) {
    EXPECT_TRUE(first.contains(key)) << key;
  }
  // A session that started with feedback only records none.
  EXPECT_TRUE(load_manifest(taught).first_correction.is_null());
}

// A law that learns its model (noilc-learned, issue 27): each trial from the second on carries how far
// it was from its model's prediction, the RMS list shows it, and each refit is a session event of its
// own ("model-refit", as `bellows run` records it). The paper's law shows and records none.
TEST_F(UiSessions, ALawThatLearnsItsModelShowsEachTrialAgainstItsPredictionAndSavesEachRefit) {
  StoreSessionGateway gateway("sim");
  Configuration config;
  config.ilc.law = "noilc-learned";
  ConsoleFixture f(config, 3, &gateway);
  f.arm_valves();
  f.run_batch(3);  // iterations 0..3: learned after 0, 1 and 2
  save_and_wait(f);
  const auto& trials = f.state().experiment.trials;
  ASSERT_EQ(trials.size(), 4u);
  EXPECT_FALSE(trials[0].model_check.has_value());  // the first update has nothing to compare with
  for (int i = 1; i <= 2; ++i) {
    const auto& check = trials[static_cast<std::size_t>(i)].model_check;
    ASSERT_TRUE(check.has_value()) << "iteration " << i;
    EXPECT_GT(check->measured_change, 0.0);
    EXPECT_GT(check->predicted_change, 0.0);
    EXPECT_GE(check->miss, 0.0);
  }
  ui::Canvas canvas(f.state().width, f.state().height);
  ui::render(f.state(), canvas);
  EXPECT_NE(canvas.text().find("  it       RMS   miss"), std::string::npos) << canvas.text();
  const std::string location = f.state().experiment.session_location;
  f.console.reset();
  int refits = 0;
  for (const SessionEvent& e : load_manifest(location).events) {
    if (e.kind == "model-refit") {
      ++refits;
      EXPECT_EQ(e.message.rfind("noilc-learned: ", 0), 0u) << e.message;
    }
    EXPECT_EQ(e.message.find("model-refit"), std::string::npos) << "in a console-log line: " << e.message;
  }
  EXPECT_EQ(refits, 2);  // the updates after iterations 1 and 2 (the first refits nothing)

  ConsoleFixture paper(Configuration{}, 3);
  paper.arm_valves();
  paper.run_batch(2);
  for (const ui::Trial& t : paper.state().experiment.trials) EXPECT_FALSE(t.model_check.has_value());
  ui::Canvas plain(paper.state().width, paper.state().height);
  ui::render(paper.state(), plain);
  EXPECT_EQ(plain.text().find("RMS   miss"), std::string::npos);
}

}  // namespace
}  // namespace bellows
