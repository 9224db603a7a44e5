// The event log tells the truth in order (issue 23): entries in the order things happened, each
// state change with its real cause, and its screen stops at the oldest entry with a full page.
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "tests/console_fixture.hpp"
#include "ui/render.hpp"
#include "ui/render_parts.hpp"

namespace bellows::ui {
namespace {

using testing::ConsoleFixture;

bool log_has(const std::string& text, const std::string& fragment) { return text.find(fragment) != std::string::npos; }

int log_index_of(const ConsoleFixture& f, const std::string& fragment) {
  const auto& entries = f.state().log.entries();
  for (std::size_t i = 0; i < entries.size(); ++i) {
    if (log_has(entries[i].text, fragment)) return static_cast<int>(i);
  }
  return -1;
}

TEST(UiEventLog, EntriesInTheOrderThingsHappenedWithTheirRealCause) {
  ConsoleFixture f;
  f.arm_valves();
  f.run_batch(2);  // iterations 0..2
  const int last_trial = log_index_of(f, "iteration 2: RMS");
  const int done = log_index_of(f, "iterations 0..2 done");
  ASSERT_GE(last_trial, 0);
  ASSERT_GE(done, 0);
  EXPECT_LT(last_trial, done);
  // The trial's own end: between its result and the batch's end, named for what it was.
  int trial_end = -1;
  for (int i = last_trial; i < done; ++i) {
    if (f.state().log.entries()[static_cast<std::size_t>(i)].text == "RUNNING -> ARMED (trial complete)") trial_end = i;
  }
  EXPECT_GT(trial_end, last_trial) << "the trial's end is not logged before the batch's end";
  EXPECT_EQ(log_index_of(f, "RUNNING -> ARMED (start trial)"), -1);
  EXPECT_GE(log_index_of(f, "ARMED -> RUNNING (start trial)"), 0);  // the start keeps its command
  // Engine times never go back between entries that have one.
  double previous = -1.0;
  for (const LogEntry& e : f.state().log.entries()) {
    if (e.engine_time_s < 0.0) continue;
    EXPECT_GE(e.engine_time_s, previous) << e.text;
    previous = e.engine_time_s;
  }
}

TEST(UiEventLog, PgUpAndHomeStopAtTheTopWithAFullPage) {
  ConsoleFixture f;
  f.arm_valves();
  f.run_batch(3);
  f.console->resize(80, 24);
  const int rows = 24 - 6;  // the log's inner height
  ASSERT_GT(static_cast<int>(f.state().log.entries().size()), rows) << "too few entries to scroll";
  f.key('l');
  for (int k : {key::kPageUp, key::kHome}) {
    for (int i = 0; i < 30; ++i) f.key(k);
    const int top = f.state().log_scroll;
    EXPECT_EQ(top, detail::log_top_scroll(f.state()));
    EXPECT_GT(top, 0);
    f.key(k);  // past the top: stays
    EXPECT_EQ(f.state().log_scroll, top);
    const std::vector<std::string> lines = render_lines(f.state());
    EXPECT_TRUE(log_has(lines[3], "console started")) << lines[3];  // the oldest entry, on the first row
    EXPECT_NE(lines[2 + rows].find_first_not_of(" |\u2502"), std::string::npos) << "blank rows under the top";
    f.key(key::kEnd);
    EXPECT_EQ(f.state().log_scroll, 0);
  }
}

}  // namespace
}  // namespace bellows::ui
