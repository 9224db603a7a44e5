// The console's commands and their keys: one table that the key handling, the help screen and the
// function bar all read, and the rule of when each command is available.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "ui/console_state.hpp"

namespace bellows::ui {

enum class Action {
  kHelp,
  kEmergencyStop,
  kArm,
  kDisarm,
  kReset,
  kTrajectory,
  kRunTrial,
  kNextIteration,
  kRunIterations,
  kStopRun,
  kInspector,
  kTuning,
  kLog,
  kFaultView,
  kSave,
  kOpen,
  kFigures,
  kQuit,
  kHeartbeatDrill,
  kRig,
  kJoint,
  kMain,
  kWorstError,  // the inspector's cursor to the largest |error| of the trial, then the next ones
  kRmsScale,    // the RMS plot on a log or a linear scale
};

struct KeyBinding {
  Action action;
  int key;
  int alt_key;            // key::kNone if none
  const char* key_label;  // as the help screen shows it, e.g. "?/F1"
  const char* bar_label;  // short, for the function bar
  const char* description;
};

/// When `q` asks before quitting: written once, shown by the help and quoted by docs/console.md.
/// Live: ARMED or RUNNING (or trials running); lost: a save failed, or saving is not available.
inline constexpr const char* kQuitRule =
    "quit: asks while the valves are live or work would be lost; otherwise saves, vents and exits";

/// Every global command, in the help screen's order.
const std::vector<KeyBinding>& key_bindings();
const KeyBinding& binding(Action action);
std::optional<Action> action_for_key(int key);

struct Availability {
  bool available = true;
  std::string reason;  // why not, for the operator
};
Availability availability(Action action, const ConsoleState& state);

/// The commands that matter in the current state, most important first (the function bar).
std::vector<Action> function_bar_actions(const ConsoleState& state);

/// A key as the operator knows it: "z", "Left", "F5" (for messages about keys).
std::string key_name(int key);

/// The key that takes an offered transfer (main screen, only while an offer stands; issue 13).
inline constexpr int kTransferKey = 'T';

/// Keys of a screen beyond the global ones: (key, what it does). The screens' key handling
/// (console_screens.cpp, console_rig.cpp, console_transfer.cpp) answers exactly these.
std::vector<std::pair<std::string, std::string>> screen_keys(Screen screen);

/// The screen as the help names it: "Correction inspector".
const char* screen_title(Screen screen);

/// One line of the help: a section title (`section`), or a key, what it does and whether it is
/// available now (with the reason when not).
struct HelpEntry {
  bool section = false;
  std::string keys;
  std::string what;
  Availability availability;
};

/// The whole help, built from key_bindings() and screen_keys() so it cannot drift from them: the
/// keys of the screen help was opened from, then the global ones, then every other screen's.
std::vector<HelpEntry> help_entries(const ConsoleState& state);

}  // namespace bellows::ui
