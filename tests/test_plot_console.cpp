// The console's figure key (g): the figures of the saved session, drawn from its files on disk as
// `bellows sessions plot` draws them (the console keeps only its newest trials in memory), on a
// background task while a batch of trials goes on, into a new folder each time.
#include <gtest/gtest.h>

#include <cstdlib>
#include <regex>

#include "app/console_sessions.hpp"
#include "app/plot_command.hpp"
#include "app/plot_console.hpp"
#include "engine/base/errors.hpp"
#include "sessions/session_store.hpp"
#include "tests/console_fixture.hpp"
#include "tests/session_test_support.hpp"

namespace bellows {
namespace {

namespace fs = std::filesystem;

/// The data directory ($XDG_DATA_HOME) in a fresh temporary directory for one test.
class PlotConsole : public ::testing::Test {
 protected:
  void SetUp() override {
    const char* previous = std::getenv("XDG_DATA_HOME");
    had_previous_ = previous != nullptr;
    if (had_previous_) previous_ = previous;
    setenv("XDG_DATA_HOME", dir_.path().c_str(), 1);
  }
  void TearDown() override {
    if (had_previous_) setenv("XDG_DATA_HOME", previous_.c_str(), 1);
    else unsetenv("XDG_DATA_HOME");
  }
  /// The figure key's writer as `bellows console` wires it: the gateway's files, read quietly.
  std::function<std::string(const std::string&, int)> writer(StoreSessionGateway& gateway) {
    return [this, &gateway](const std::string& location, int iterations) {
      ++calls_;
      return write_console_figures(location, iterations, root_,
                                   [&gateway](const std::function<void()>& read) { gateway.read_quietly(read); });
    };
  }
  std::vector<fs::path> folders() const {
    std::vector<fs::path> out;
    for (const auto& entry : fs::directory_iterator(root_)) out.push_back(entry.path());
    std::sort(out.begin(), out.end());
    return out;
  }

  testing::TempDir dir_;
  fs::path root_ = dir_ / "figures";
  std::atomic<int> calls_{0};
  bool had_previous_ = false;
  std::string previous_;
};

std::string log_of(const testing::ConsoleFixture& f) {
  std::string all = f.state().status + "\n";
  for (const ui::LogEntry& e : f.state().log.entries()) all += e.text + "\n";
  return all;
}

/// The rows of the gnuplot data block `$name` in a figures.gp script; -1 when it is not there.
int block_rows(const std::string& script, const std::string& name) {
  const std::string head = "$" + name + " << EOD\n";
  const std::size_t start = script.find(head);
  if (start == std::string::npos) return -1;
  const std::size_t end = script.find("EOD\n", start + head.size());
  const std::string body = script.substr(start + head.size(), end - start - head.size());
  return static_cast<int>(std::count(body.begin(), body.end(), '\n'));
}

TEST_F(PlotConsole, TheFigureKeyWritesFiguresWhileTheBatchGoesOn) {
  StoreSessionGateway gateway("sim");
  testing::ConsoleFixture f(Configuration{}, 3, &gateway, nullptr, writer(gateway));
  f.key('g');
  EXPECT_NE(f.state().status.find("no trial has run yet"), std::string::npos) << f.state().status;
  f.arm_valves();
  // A batch of iterations 0..2 (K = 2, docs/iterations.md); the key after its first trial.
  f.key('N');
  f.key(ui::key::kBackspace);
  f.key(ui::key::kBackspace);
  f.type("2");
  f.key(ui::key::kEnter);
  ASSERT_TRUE(f.pump_until([&] { return f.state().experiment.trials.size() >= 1; }));
  f.key('g');
  ASSERT_TRUE(f.pump_until([&] { return f.idle(); }));
  ASSERT_TRUE(f.pump_until([&] { return f.logged("figures written to"); }, 1e6)) << log_of(f);  // limited by wall time
  EXPECT_EQ(calls_, 1);
  EXPECT_EQ(f.state().experiment.trials.size(), 3u);  // the batch was not stopped
  EXPECT_EQ(f.state().engine_state, EngineState::kArmed);
  const std::string session = fs::path(f.state().experiment.session_location).filename().string();
  std::vector<fs::path> written = folders();
  ASSERT_EQ(written.size(), 1u);
  // Named after the saved session and the iterations it had when the key was pressed (the first).
  EXPECT_EQ(written[0].filename().string(), session + "_iteration_0000") << written[0];
  for (const std::string name :
       {"rms.png", "rms.svg", "angle.svg", "error.png", "u_ilc.png", "pressures.svg", "figures.gp"}) {
    EXPECT_GT(fs::file_size(written[0] / name), 0u) << name;
  }
  EXPECT_EQ(block_rows(testing::read_text(written[0] / "figures.gp"), "rms"), 1);
  // Again after the batch: a second folder, nothing replaced.
  f.key('g');
  ASSERT_TRUE(f.pump_until([&] { return f.logged("_iteration_0002"); }, 1e6)) << log_of(f);
  EXPECT_EQ(calls_, 2);
  EXPECT_EQ(folders().size(), 2u);
  // The paper trajectory: the log says whether the paper's curve is in the figures.
  const bool paper_there = fs::is_regular_file(default_paper_rms_path());
  EXPECT_EQ(f.logged("paper's RMS curve: not overlaid"), !paper_there) << log_of(f);
}

// Issue 23: with more than 8 iterations the console has released the early trials' records (the
// session on disk has them), and the figures' data blocks of those iterations were empty.
TEST_F(PlotConsole, AReopenedSessionsFiguresHoldEveryIteration) {
  std::string location;
  {
    StoreSessionGateway gateway("sim");
    testing::ConsoleFixture f(Configuration{}, 100, &gateway);
    f.arm_valves();
    f.run_batch(9);  // iterations 0..9
    ASSERT_TRUE(f.pump_until([&] { return f.console->saves_settled(); }));
    ASSERT_EQ(f.state().experiment.saved_trials, 10) << log_of(f);
    location = f.state().experiment.session_location;
  }
  StoreSessionGateway gateway("sim");
  testing::ConsoleFixture f(Configuration{}, 100, &gateway, nullptr, writer(gateway));
  ASSERT_TRUE(f.pump_until([&] { return f.state().law_ready; }));
  f.key('o');
  ASSERT_TRUE(f.pump_until([&] { return !f.state().browser.loading; }));
  f.key(ui::key::kEnter);
  ASSERT_TRUE(f.pump_until([&] { return !f.state().learner_busy && f.state().law_ready; }));
  ASSERT_EQ(f.state().experiment.trials.size(), 10u) << log_of(f);
  f.arm_valves();
  for (int i = 0; i < 2; ++i) {
    f.key('n');
    ASSERT_TRUE(f.pump_until([&] { return f.idle(); }));
  }
  ASSERT_EQ(f.state().experiment.trials.size(), 12u);
  // What the bug drew from: iteration 0's record is on disk only.
  EXPECT_FALSE(f.state().experiment.trials[0].in_memory());
  f.key('g');
  ASSERT_TRUE(f.pump_until([&] { return f.logged("figures written to"); }, 1e6)) << log_of(f);
  const std::vector<fs::path> written = folders();
  ASSERT_EQ(written.size(), 1u);
  EXPECT_EQ(written[0].filename().string(), fs::path(location).filename().string() + "_iteration_0011");
  const std::string script = testing::read_text(written[0] / "figures.gp");
  EXPECT_EQ(block_rows(script, "rms"), 12);  // every iteration's RMS
  // The drawn iterations (first, second, middle, last) each hold a full trial: N + 1 samples.
  const int samples = f.state().experiment.samples() + 1;
  for (int j : {0, 1, 6, 11}) EXPECT_EQ(block_rows(script, "iteration_" + std::to_string(j)), samples) << j;
  // No data block in the script is empty.
  const std::regex empty_block(R"(\$\w+ << EOD\nEOD\n)");
  EXPECT_FALSE(std::regex_search(script, empty_block));
  // The same figures `bellows sessions plot` draws from the same files.
  f.console.reset();
  FigureRequest request;
  add_paper_curve(request, "paper", {}, false);
  const std::vector<Figure> figures = session_figures(read_figure_session(location, request), request);
  EXPECT_EQ(script, gnuplot_script(figures, request.formats)) << "the console's figures differ from sessions plot's";
}

TEST_F(PlotConsole, WithoutASavedSessionThereAreNoFigures) {
  EXPECT_THROW(write_console_figures("", 0, "/tmp", [](const std::function<void()>& read) { read(); }), InputError);
  EXPECT_THROW(
      write_console_figures((dir_ / "none").string(), 3, root_, [](const std::function<void()>& read) { read(); }),
      InputError);
}

}  // namespace
}  // namespace bellows
