// The main screen's layout at 80x24, 120x40 and 200x60 (issue 23): the RMS list keeps inside its own
// columns (its best mark never overwrites the frame beside its plot), the log panel uses the width
// a wide window has, the header names only the weights the active law uses, and a status message
// shows on the screen it was said on only.
#include <gtest/gtest.h>

#include <string>
#include <utility>
#include <vector>

#include "tests/ui_sample_state.hpp"
#include "ui/canvas.hpp"
#include "ui/render.hpp"

namespace bellows::ui {
namespace {

using testing::all;
using testing::sample_state;

bool layout_has(const std::string& text, const std::string& fragment) {
  return text.find(fragment) != std::string::npos;
}

const std::vector<std::pair<int, int>> kLayoutSizes = {{80, 24}, {120, 40}, {200, 60}};

TEST(UiRenderLayout, TheRmsListKeepsInsideItsPanel) {
  for (const auto& [width, height] : kLayoutSizes) {
    for (int trials : {3, 16, 40}) {
      SCOPED_TRACE(std::to_string(width) + "x" + std::to_string(height) + ", " + std::to_string(trials) +
                   " iterations");
      ConsoleState s = sample_state(trials, true);
      s.width = width;
      s.height = height;
      const std::vector<std::string> lines = render_lines(s);
      const std::string best = format("%9.3f*", 10.0 / trials);  // the newest is the best here
      int found = 0;
      for (const std::string& line : lines) {
        if (!layout_has(line, best)) continue;
        ++found;
        // The RMS panel's right edge, then the correction panel's left edge: both frames whole.
        EXPECT_TRUE(layout_has(line, best + "\u2502\u2502")) << line;
      }
      EXPECT_EQ(found, 1) << all(lines);
    }
  }
}

TEST(UiRenderLayout, TheLogPanelUsesTheWidthAWideWindowHas) {
  ConsoleState s = sample_state(3, true);
  s.width = 200;
  s.height = 60;
  s.log.add({"12:00:03",
             2.0,
             LogSource::kOperator,
             "a log line that a 200 column window shows whole",
             false,
             false,
             "",
             0,
             {}});
  const std::string screen = all(render_lines(s));
  EXPECT_TRUE(layout_has(screen, "a log line that a 200 column window shows whole"))
      << screen;  // cut at 29 columns before
}

TEST(UiRenderLayout, TheHeaderNamesOnlyTheWeightsOfTheActiveLaw) {
  for (const auto& [width, height] : kLayoutSizes) {
    if (width < 120) continue;  // the compact header drops the weights (the tuning screen has them)
    ConsoleState s = sample_state(3, true);
    s.width = width;
    s.height = height;
    EXPECT_TRUE(layout_has(render_lines(s)[1], "M 1 S 0.1 W 2e-05")) << render_lines(s)[1];
    s.config.ilc.law = s.law_name = "pd";
    EXPECT_TRUE(layout_has(render_lines(s)[1], "k_p 0.3 k_d 0.01 s Q 3.5 Hz")) << render_lines(s)[1];
    EXPECT_FALSE(layout_has(render_lines(s)[1], "W 2e-05")) << render_lines(s)[1];
    s.config.ilc.law = s.law_name = "gradient";
    EXPECT_TRUE(layout_has(render_lines(s)[1], "step 1")) << render_lines(s)[1];
    EXPECT_FALSE(layout_has(render_lines(s)[1], "M 1")) << render_lines(s)[1];
    s.config.ilc.law = s.law_name = "inverse";
    EXPECT_TRUE(layout_has(render_lines(s)[1], "gain 0.3 Q 8 Hz")) << render_lines(s)[1];
  }
}

TEST(UiRenderLayout, AStatusShowsOnTheScreenItWasSaidOn) {
  for (const auto& [width, height] : kLayoutSizes) {
    ConsoleState s = sample_state(3, true);
    s.width = width;
    s.height = height;
    s.status = "said on the main screen";
    s.status_screen = Screen::kMain;
    EXPECT_TRUE(layout_has(all(render_lines(s)), "said on the main screen"));
    s.screen = Screen::kLog;
    EXPECT_FALSE(layout_has(all(render_lines(s)), "said on the main screen"));
  }
}

}  // namespace
}  // namespace bellows::ui
