#include "ui/key_map.hpp"

#include "ui/canvas.hpp"
#include "ui/keys.hpp"

namespace bellows::ui {
namespace {

bool run_idle(const ConsoleState& s) { return s.run.mode == RunProgress::Mode::kIdle; }

Availability no(std::string why) { return {false, std::move(why)}; }

Availability needs_armed_idle(const ConsoleState& s) {
  switch (s.engine_state) {
    case EngineState::kSafe:
      return no("arm the valves first (a)");
    case EngineState::kFault:
      return no("a fault is latched: reset it (R), then arm");
    case EngineState::kRunning:
      return no("a trial is running");
    case EngineState::kArmed:
      break;
  }
  if (!run_idle(s)) return no("trials are running (x stops them)");
  return {};
}

}  // namespace

const std::vector<KeyBinding>& key_bindings() {
  static const std::vector<KeyBinding> bindings = {
      {Action::kHelp, '?', key::kF1, "?/F1", "Help", "help: every key, greyed when not available now"},
      {Action::kEmergencyStop, ' ', key::kNone, "Space", "E-STOP", "emergency stop: vent at once (every screen)"},
      {Action::kArm, 'a', key::kNone, "a", "Arm", "arm the valves (asks for confirmation)"},
      {Action::kDisarm, 'd', key::kNone, "d", "Disarm", "disarm: vent, abandoning a running trial"},
      {Action::kReset, 'R', key::kNone, "R", "Reset", "reset a latched fault (then arm again)"},
      {Action::kTrajectory, 't', key::kNone, "t", "Traj", "choose the trajectory (library or file), with a preview"},
      {Action::kRunTrial, 'r', key::kNone, "r", "Run", "run a trial with the current correction, no learning"},
      {Action::kNextIteration, 'n', key::kNone, "n", "Next", "next ILC iteration: learn from the last trial, then run"},
      {Action::kRunIterations, 'N', key::kNone, "N", "Run K", "run K iterations (asks for K; x interrupts)"},
      {Action::kStopRun, 'x', key::kNone, "x", "Stop", "stop the trials: abort the running one, keep the valves armed"},
      {Action::kInspector, 'c', key::kNone, "c", "Inspect", "correction inspector: cursor along time and iterations"},
      {Action::kTuning, 'w', key::kNone, "w", "Tune", "learning weights M, S, W and PID gains (between trials)"},
      {Action::kLog, 'l', key::kNone, "l", "Log", "event log: everything the operator and the engine did"},
      {Action::kFaultView, 'f', key::kNone, "f", "Fault", "the last fault: which guard fired and the black box"},
      {Action::kSave, 's', key::kNone, "s", "Name", "name the session (it is saved as you go)"},
      {Action::kOpen, 'o', key::kNone, "o", "Open", "open a saved session"},
      {Action::kFigures, 'g', key::kNone, "g", "Figures",
       "figures from the saved files: RMS, angle, error, u_ilc, pressures as PNG and SVG"},
      {Action::kQuit, 'q', key::kNone, "q", "Quit", kQuitRule},
      {Action::kHeartbeatDrill, 'H', key::kNone, "H", "Drill",
       "heartbeat drill: withhold heartbeats until the engine vents"},
      {Action::kRig, 'b', key::kNone, "b", "Rig",
       "the Rig screen (the first day at the bench): inputs live, valve test"},
      {Action::kJoint, 'j', key::kNone, "j", "Joint",
       "next joint: the live strip, plots and inspector show it (arms with several joints)"},
      {Action::kMain, key::kEscape, key::kNone, "Esc", "Back", "back to the main screen"},
      {Action::kWorstError, 'e', key::kNone, "e", "Worst",
       "the inspector at the largest |error| of the trial; again: the next largest (E: back)"},
      {Action::kRmsScale, 'L', key::kNone, "L", "Log RMS",
       "the RMS plot on a log or a linear scale (the largest error per iteration beside it)"},
  };
  return bindings;
}

const KeyBinding& binding(Action action) {
  for (const KeyBinding& b : key_bindings()) {
    if (b.action == action) return b;
  }
  return key_bindings().front();
}

std::optional<Action> action_for_key(int k) {
  for (const KeyBinding& b : key_bindings()) {
    if (b.key == k || (b.alt_key != key::kNone && b.alt_key == k)) return b.action;
  }
  return std::nullopt;
}

Availability availability(Action action, const ConsoleState& s) {
  switch (action) {
    case Action::kHelp:
    case Action::kEmergencyStop:
    case Action::kLog:
    case Action::kTuning:
    case Action::kQuit:
    case Action::kMain:
    case Action::kRig:
      return {};
    case Action::kArm:
      if (s.engine_state == EngineState::kFault) return no("a fault is latched: reset it first (R)");
      if (s.engine_state != EngineState::kSafe) return no("already armed");
      return {};
    case Action::kDisarm:
      if (s.engine_state == EngineState::kArmed || s.engine_state == EngineState::kRunning) return {};
      return no("the valves are not armed");
    case Action::kReset:
      if (s.engine_state == EngineState::kFault) return {};
      return no("no fault is latched");
    case Action::kTrajectory:
      if (!run_idle(s) || s.engine_state == EngineState::kRunning) return no("not while trials run");
      return {};
    case Action::kRunTrial:
      return needs_armed_idle(s);
    case Action::kNextIteration: {
      Availability a = needs_armed_idle(s);
      if (a.available && s.experiment.next_tried && !s.law_ready) return no("the learning law is not ready yet");
      return a;
    }
    case Action::kRunIterations: {
      Availability a = needs_armed_idle(s);
      if (a.available && !s.law_ready) return no("the learning law is not ready yet");
      return a;
    }
    case Action::kStopRun:
      if (run_idle(s)) return no("no trials are running");
      return {};
    case Action::kInspector:
    case Action::kWorstError:
    case Action::kRmsScale:
      if (s.experiment.trials.empty()) return no("no trial has run yet");
      return {};
    case Action::kFaultView:
      if (s.fault_view.code == FaultCode::kNone) return no("no fault so far");
      return {};
    case Action::kSave:
      if (!s.sessions_available) return no(s.sessions_unavailable_reason);
      if (s.experiment.session_location.empty())
        return no("nothing to name yet: the session is saved from the first trial on");
      return {};
    case Action::kFigures:
      if (s.experiment.trials.empty()) return no("no trial has run yet");
      if (!s.sessions_available)
        return no("figures are drawn from the saved session: " + s.sessions_unavailable_reason);
      return {};
    case Action::kOpen:
      if (!s.sessions_available) return no(s.sessions_unavailable_reason);
      if (!run_idle(s) || valves_live(s.engine_state)) return no("disarm first (d): opening replaces the session");
      return {};
    case Action::kJoint:
      if (s.experiment.joints() < 2) return no("the arm has one joint");
      return {};
    case Action::kHeartbeatDrill: {
      if (s.loop.clock == "sim") return no("the simulated clock has no heartbeat to withhold (--clock wall has)");
      Availability a = needs_armed_idle(s);
      if (a.available && s.heartbeat_drill) return no("the drill is running");
      return a;
    }
  }
  return {};
}

std::vector<Action> function_bar_actions(const ConsoleState& s) {
  std::vector<Action> candidates;
  if (s.engine_state == EngineState::kFault) {
    candidates = {Action::kReset, Action::kFaultView, Action::kLog, Action::kTrajectory, Action::kHelp, Action::kQuit};
  } else if (!run_idle(s) || s.engine_state == EngineState::kRunning) {
    candidates = {Action::kEmergencyStop, Action::kStopRun, Action::kDisarm, Action::kJoint,
                  Action::kInspector,     Action::kLog,     Action::kHelp,   Action::kQuit};
  } else if (s.engine_state == EngineState::kArmed) {
    candidates = {Action::kEmergencyStop, Action::kRunTrial, Action::kNextIteration, Action::kRunIterations,
                  Action::kDisarm,        Action::kJoint,    Action::kInspector,     Action::kTrajectory,
                  Action::kTuning,        Action::kSave,     Action::kHelp,          Action::kQuit};
  } else {
    candidates = {Action::kArm,    Action::kJoint, Action::kTrajectory, Action::kInspector,
                  Action::kTuning, Action::kSave,  Action::kOpen,       Action::kRig,
                  Action::kLog,    Action::kHelp,  Action::kQuit};
  }
  if (s.screen == Screen::kInspector) candidates.insert(candidates.begin() + 1, Action::kWorstError);
  if (s.screen != Screen::kMain) {  // on every other screen: the way back, right after the stop
    const bool stop_first = candidates.front() == Action::kEmergencyStop;
    candidates.insert(candidates.begin() + (stop_first ? 1 : 0), Action::kMain);
  }
  std::vector<Action> shown;
  for (Action a : candidates) {
    if (availability(a, s).available) shown.push_back(a);
  }
  return shown;
}

std::string key_name(int k) {
  switch (k) {
    case key::kEnter:
      return "Enter";
    case key::kEscape:
      return "Esc";
    case key::kUp:
      return "Up";
    case key::kDown:
      return "Down";
    case key::kLeft:
      return "Left";
    case key::kRight:
      return "Right";
    case key::kPageUp:
      return "PgUp";
    case key::kPageDown:
      return "PgDn";
    case key::kHome:
      return "Home";
    case key::kEnd:
      return "End";
    case key::kBackspace:
      return "Backspace";
    case key::kF1:
      return "F1";
    case key::kTab:
      return "Tab";
    case ' ':
      return "Space";
    default:
      break;
  }
  if (k > 0x20 && k < 0x7f) return std::string(1, static_cast<char>(k));
  if (k >= 0 && k < 0x20) return "Ctrl-" + std::string(1, static_cast<char>('@' + k));
  if (k >= 0x80 && k < key::kSpecial) {
    std::string text;
    append_utf8(text, static_cast<char32_t>(k));
    return text;
  }
  return "this key";
}

std::vector<std::pair<std::string, std::string>> screen_keys(Screen screen) {
  switch (screen) {
    case Screen::kInspector:
      return {
          {"Left/Right", "cursor along time, one sample"},
          {"PgUp/PgDn", "cursor along time, a tenth of the trial"},
          {"Home/End", "start / end of the trial"},
          {"Up/Down", "earlier / later iteration"},
          {"e / E", "the largest |error| of the trial, then the next largest / back to the larger one"},
          {"m", "overlay this iteration for comparison, with the differences du, de and their RMS (m again: remove)"},
          {"u", "use this iteration's correction for the next trial"}};
    case Screen::kTrajectory:
      return {{"Up/Down", "choose; the preview follows"}, {"Enter", "use it (the file entry asks for a path)"}};
    case Screen::kTuning:
      return {{"Up/Down", "choose a value"},
              {"Enter", "change it (between trials; recorded in the log)"},
              {"Left/Right", "on the law row: the previous / next learning law"}};
    case Screen::kSessions:
      return {{"Up/Down", "choose a session"}, {"Enter", "open it"}};
    case Screen::kLog:
      return {{"Up/Down, PgUp/PgDn", "scroll"}, {"Home/End", "oldest / newest"}};
    case Screen::kFault:
      return {{"R", "reset the fault"}};
    case Screen::kRig:
      return {{"v", "valve test: each valve alone, pass or fail (asks first; arms, disarms after)"},
              {"z", "zero the angle: the angle read now becomes the rig profile's zero (asks first; t7)"}};
    case Screen::kMain:
      return {{key_name(kTransferKey), "start a new trajectory from what earlier sessions taught (only while offered)"},
              {"L", "the RMS plot on a log or a linear scale"}};
    case Screen::kHelp:
      return {{"Up/Down, PgUp/PgDn", "scroll"},
              {"Home/End", "top / bottom"},
              {"q, Esc, ?/F1", "close the help: back to the screen it was opened from"}};
  }
  return {};
}

const char* screen_title(Screen screen) {
  switch (screen) {
    case Screen::kMain:
      return "Main screen";
    case Screen::kHelp:
      return "This help";
    case Screen::kTrajectory:
      return "Trajectory chooser (t)";
    case Screen::kInspector:
      return "Correction inspector (c)";
    case Screen::kTuning:
      return "Tuning (w)";
    case Screen::kLog:
      return "Event log (l)";
    case Screen::kSessions:
      return "Session browser (o)";
    case Screen::kFault:
      return "Fault view (f)";
    case Screen::kRig:
      return "Rig screen (b)";
  }
  return "";
}

std::vector<HelpEntry> help_entries(const ConsoleState& s) {
  std::vector<HelpEntry> out;
  const auto add_screen = [&](Screen screen, const std::string& title) {
    const auto keys = screen_keys(screen);
    if (keys.empty()) return;
    out.push_back({true, "", title, {}});
    for (const auto& [k, what] : keys) out.push_back({false, k, what, {}});
  };
  const Screen from = s.previous_screen;
  if (from != Screen::kMain) add_screen(from, std::string("On the screen you came from: ") + screen_title(from));
  out.push_back({true, "", "Everywhere (greyed: not available now)", {}});
  for (const KeyBinding& b : key_bindings())
    out.push_back({false, b.key_label, b.description, availability(b.action, s)});
  out.push_back({false, "Ctrl-L", "repaint the whole screen (also in prompts and questions)", {}});
  out.push_back({true, "", "In a prompt or a question (every key goes to it; Space still stops)", {}});
  for (const auto& [k, what] : std::vector<std::pair<std::string, std::string>>{
           {"Enter", "take the answer (refused: the prompt stays open, what was typed kept, and says why)"},
           {"Backspace", "delete the last character typed"},
           {"Ctrl-U", "clear the field"},
           {"Esc", "cancel: back to the screen beneath, nothing done"},
           {"y / n", "answer a question (quitting: q or y quits, s saves first)"}})
    out.push_back({false, k, what, {}});
  for (Screen screen : {Screen::kMain, Screen::kInspector, Screen::kTrajectory, Screen::kTuning, Screen::kSessions,
                        Screen::kLog, Screen::kFault, Screen::kRig, Screen::kHelp}) {
    if (screen != from || from == Screen::kMain) add_screen(screen, screen_title(screen));
  }
  return out;
}

}  // namespace bellows::ui
