// The help screen: built from the one key table, it lists every key of every screen (the global
// commands with the reason when one is not available now, then each screen's own keys, `T`
// included), wraps instead of cutting, and scrolls through all of it at 80x24.
#include <gtest/gtest.h>

#include <fstream>
#include <iterator>
#include <regex>

#include "tests/ui_sample_state.hpp"
#include "ui/key_map.hpp"
#include "ui/render.hpp"
#include "ui/render_parts.hpp"

namespace bellows::ui {
namespace {

using testing::sample_state;

constexpr int kKeyColumnEnd = 22;  // the help draws keys in columns 2..21, what they do from 23 on

struct HelpText {
  std::string keys;  // the key column of every line, one per line
  std::string what;  // the description column, wrapped lines joined by one space
};

bool is_section_title(std::string line, const ConsoleState& s) {
  line.erase(line.find_last_not_of(' ') + 1);
  if (line.empty()) return false;
  for (const HelpEntry& e : help_entries(s)) {
    if (e.section && e.what == line) return true;
  }
  return false;
}

/// Every page of the help, scrolled with its own state as the Down/PgDn keys would, read as text.
HelpText read_help(ConsoleState s) {
  s.screen = Screen::kHelp;
  s.unicode = false;  // one byte per column
  HelpText out;
  const int page = s.height - 6;
  const int total = detail::help_line_count(s);
  for (s.help_scroll = 0;; s.help_scroll += page) {
    const std::vector<std::string> lines = render_lines(s);
    for (int y = 3; y < 3 + page && y < static_cast<int>(lines.size()); ++y) {
      const std::string& line = lines[static_cast<std::size_t>(y)];
      const std::string inside = line.substr(2, line.size() - 4);
      if (is_section_title(inside, s)) {  // titles start in the key column
        out.what += inside + " ";
        continue;
      }
      out.keys += line.substr(2, kKeyColumnEnd - 2) + "\n";
      out.what += line.substr(kKeyColumnEnd + 1, line.size() - kKeyColumnEnd - 2) + " ";
    }
    if (s.help_scroll + page >= total) break;
  }
  out.what = std::regex_replace(out.what, std::regex(" +"), " ");
  return out;
}

bool has_key(const HelpText& h, const std::string& label) {
  return std::regex_search(
      h.keys,
      std::regex("(^|\\n)" + std::regex_replace(label, std::regex("[?/.^$*+()\\[\\]{}|\\\\]"), "\\$&") + " *\\n"));
}

TEST(UiHelp, EveryKeyOfEveryScreenIsInTheHelpAt80x24) {
  for (Screen from : {Screen::kMain, Screen::kInspector, Screen::kRig, Screen::kSessions}) {
    for (EngineState state : {EngineState::kSafe, EngineState::kArmed, EngineState::kFault}) {
      ConsoleState s = sample_state(0, false);
      s.width = kMinWidth;
      s.height = kMinHeight;
      s.engine_state = state;
      s.previous_screen = from;
      const HelpText h = read_help(s);
      SCOPED_TRACE(h.keys);
      for (const KeyBinding& b : key_bindings()) {
        EXPECT_TRUE(has_key(h, b.key_label)) << b.key_label;
        EXPECT_NE(h.what.find(b.description), std::string::npos) << b.description << "\n" << h.what;
        const Availability a = availability(b.action, s);
        if (!a.available && !a.reason.empty()) {
          EXPECT_NE(h.what.find("(" + a.reason + ")"), std::string::npos) << a.reason << "\n" << h.what;
        }
      }
      for (Screen screen : {Screen::kMain, Screen::kInspector, Screen::kTrajectory, Screen::kTuning, Screen::kSessions,
                            Screen::kLog, Screen::kFault, Screen::kRig, Screen::kHelp}) {
        EXPECT_NE(h.what.find(screen_title(screen)), std::string::npos) << screen_title(screen);
        for (const auto& [keys, what] : screen_keys(screen)) {
          EXPECT_TRUE(has_key(h, keys)) << keys;
          EXPECT_NE(h.what.find(what), std::string::npos) << what << "\n" << h.what;
        }
      }
      EXPECT_TRUE(has_key(h, "T"));  // the transfer's key, which exists only while an offer stands
      EXPECT_NE(h.what.find("start a new trajectory from what earlier sessions taught"), std::string::npos);
    }
  }
}

TEST(UiHelp, TheScreenHelpWasOpenedFromComesFirst) {
  ConsoleState s = sample_state(2, false);
  s.previous_screen = Screen::kInspector;
  const HelpText h = read_help(s);
  EXPECT_EQ(h.what.find("On the screen you came from: Correction inspector"), 0u) << h.what;
  EXPECT_LT(h.what.find("overlay this iteration"), h.what.find("Everywhere"));
}

TEST(UiHelp, AtEightyByTwentyFourItScrollsAndSaysWhereItIs) {
  ConsoleState s = sample_state(0, false);
  s.width = kMinWidth;
  s.height = kMinHeight;
  s.screen = Screen::kHelp;
  const int total = detail::help_line_count(s);
  ASSERT_GT(total, s.height - 6);  // more than one page: it must scroll
  std::string first = render_lines(s)[2];
  EXPECT_NE(first.find("lines 1-18 of " + std::to_string(total)), std::string::npos) << first;
  s.help_scroll = total;  // past the end: the last page, not an empty one
  const std::vector<std::string> last = render_lines(s);
  EXPECT_NE(last[2].find(std::to_string(total - 17) + "-" + std::to_string(total) + " of"), std::string::npos)
      << last[2];
  EXPECT_NE(last[20].find("close the help"), std::string::npos) << last[20];
}

}  // namespace
}  // namespace bellows::ui

namespace bellows::ui {
namespace {

// One rule of when `q` asks, written once: the help shows kQuitRule and docs/console.md quotes it.
TEST(UiHelp, TheQuitRuleIsWrittenOnceForTheHelpAndTheDocs) {
  bool in_help = false;
  for (const HelpEntry& e : help_entries(testing::sample_state(1, true)))
    in_help |= e.keys == "q" && e.what == kQuitRule;
  EXPECT_TRUE(in_help);
  std::ifstream docs(std::string(BELLOWS_SOURCE_DIR) + "/docs/console.md");
  ASSERT_TRUE(docs) << "docs/console.md";
  const std::string text((std::istreambuf_iterator<char>(docs)), std::istreambuf_iterator<char>());
  EXPECT_NE(text.find(std::string("`q` ") + kQuitRule), std::string::npos)
      << "docs/console.md does not quote kQuitRule";
  EXPECT_EQ(text.find("asks only when a save failed"), std::string::npos);
}

}  // namespace
}  // namespace bellows::ui
