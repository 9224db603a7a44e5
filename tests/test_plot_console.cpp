// The console's figure key (g): figures of the trials so far, drawn by gnuplot on a background task
// while a batch of trials goes on, into a new folder each time.
#include <gtest/gtest.h>

#include "app/plot_console.hpp"
#include "engine/base/errors.hpp"
#include "tests/console_fixture.hpp"
#include "tests/session_test_support.hpp"

namespace bellows {
namespace {

namespace fs = std::filesystem;

TEST(PlotConsole, TheFigureKeyWritesFiguresWhileTheBatchGoesOn) {
  testing::TempDir dir;
  const fs::path root = dir / "figures";
  int calls = 0;
  testing::ConsoleFixture f(Configuration{}, 3, nullptr, nullptr, [&](const ui::SessionSnapshot& snapshot) {
    ++calls;
    return write_console_figures(snapshot, root);
  });
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
  ASSERT_TRUE(f.pump_until([&] { return f.logged("figures written to"); }, 1e6));  // limited by wall time
  EXPECT_EQ(calls, 1);
  EXPECT_EQ(f.state().experiment.trials.size(), 3u);  // the batch was not stopped
  EXPECT_EQ(f.state().engine_state, EngineState::kArmed);
  std::vector<fs::path> folders;
  for (const auto& entry : fs::directory_iterator(root)) folders.push_back(entry.path());
  ASSERT_EQ(folders.size(), 1u);
  EXPECT_EQ(folders[0].filename().string().rfind("console_iteration_", 0), 0u) << folders[0];
  for (const std::string name : {"rms.png", "rms.svg", "angle.svg", "u_ilc.png", "pressures.svg", "figures.gp"}) {
    EXPECT_GT(fs::file_size(folders[0] / name), 0u) << name;
  }
  // Again after the batch: a second folder, nothing replaced.
  f.key('g');
  ASSERT_TRUE(f.pump_until([&] { return f.logged("_iteration_0002"); }, 1e6)) << f.state().status << "\n" << [&] {
    std::string all;
    for (const ui::LogEntry& e : f.state().log.entries()) all += e.text + "\n";
    return all;
  }();
  EXPECT_EQ(calls, 2);
  EXPECT_EQ(std::distance(fs::directory_iterator(root), fs::directory_iterator()), 2);
}

TEST(PlotConsole, NoTrialNoFigures) {
  ui::SessionSnapshot snapshot;
  EXPECT_THROW(write_console_figures(snapshot, "/tmp"), InputError);
}

}  // namespace
}  // namespace bellows
