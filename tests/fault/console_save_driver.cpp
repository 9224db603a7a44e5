// The console's per-trial save without a terminal (issue 24): a console controller over the real
// engine on a simulated clock (tests/console_fixture.hpp) saving into the real session store, run
// as its own process so that the fault-injection shim (fault_injection_shim.cpp) can kill it or
// fail a call of the save under test. It runs `BELLOWS_DRIVER_TRIALS` trials (default 2) saved
// unarmed, arms the shim (BELLOWS_FAULT_ARMED=1), runs one more trial (the console learns its
// correction after saving it: two saves), waits for the saves, then quits like an operator (q,
// and q again if asked); BELLOWS_DRIVER_SKIP_ARMED_TRIAL=1 quits without it (the session as it was
// before the save under test, for the tests' reference). It prints what the operator would read, one `key: value` line
// each, and exits as the console does: 4 when quitting leaves work the disk did not take, else 0.
//   console_save_driver DATA_DIR
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>

#include <gtest/gtest.h>  // console_fixture.hpp's helpers assert

#include "app/console_sessions.hpp"
#include "tests/console_fixture.hpp"

using bellows::testing::ConsoleFixture;

int main(int argc, char** argv) {
  if (argc != 2) {
    std::fprintf(stderr, "usage: console_save_driver DATA_DIR\n");
    return 2;
  }
  ::setenv("BELLOWS_FAULT_ARMED", "0", 1);
  bellows::StoreSessionGateway gateway("sim", nlohmann::ordered_json::object(), argv[1]);
  ConsoleFixture f(bellows::Configuration{}, 3, &gateway);
  const auto settle = [&] {
    return f.pump_until([&] { return f.console->saves_settled() && !f.state().learner_busy; });
  };
  const char* trials_text = std::getenv("BELLOWS_DRIVER_TRIALS");
  const int before = trials_text != nullptr ? std::atoi(trials_text) : 2;
  if (!f.pump_until([&] { return f.state().law_ready; })) return 3;
  f.key('a');
  f.key('y');
  if (!f.pump_until([&] { return f.state().engine_state == bellows::EngineState::kArmed; })) return 3;
  for (int i = 0; i < before; ++i) {
    f.key(i == 0 ? 'r' : 'n');
    if (!f.pump_until([&] { return f.idle(); }) || !settle()) return 3;
  }
  if (f.state().experiment.saved_trials != before || f.state().experiment.unsaved()) return 3;  // all on disk, unarmed
  std::printf("session: %s\n", f.state().experiment.session_location.c_str());
  std::fflush(stdout);
  const char* skip_text = std::getenv("BELLOWS_DRIVER_SKIP_ARMED_TRIAL");  // "1": quit here (the state before the save)
  const bool armed_trial = skip_text == nullptr || std::strcmp(skip_text, "1") != 0;
  ::setenv("BELLOWS_FAULT_ARMED", "1", 1);  // the save under test: the next trial's
  if (armed_trial) {
    f.key('n');
    if (!f.pump_until([&] { return f.idle(); })) return 3;
    settle();
  }
  ::setenv("BELLOWS_FAULT_ARMED", "0", 1);
  std::printf("status: %s\n", f.state().status.c_str());
  for (const bellows::ui::LogEntry& entry : f.state().log.entries()) {  // what the operator read in the log
    if (entry.text.rfind("save failed", 0) == 0) std::printf("failure: %s\n", entry.text.c_str());
  }
  f.key('q');
  f.pump_until([&] { return f.console->quit_requested() || f.state().dialog.kind != bellows::ui::DialogKind::kNone; });
  if (f.state().dialog.kind == bellows::ui::DialogKind::kConfirmQuit) {
    std::string text;
    for (const std::string& line : f.state().dialog.text) text += line + " ";
    std::printf("confirmation: %s\n", text.c_str());
    f.key('q');  // quit without saving
  }
  std::printf("quit: %s\n", f.console->quit_requested() ? "yes" : "no");
  std::printf("trials: %d\nsaved: %d\nunsaved: %s\n", static_cast<int>(f.state().experiment.trials.size()),
              f.state().experiment.saved_trials, f.console->unsaved_work().c_str());
  std::fflush(stdout);
  return f.console->quitting_loses_work() ? 4 : 0;
}
