// The operator's side of the controller: keys, dialogs and the screens' own keys.
#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <numbers>

#include "engine/errors.hpp"
#include "ui/console_controller.hpp"
#include "ui/keys.hpp"
#include "ui/render.hpp"
#include "ui/tuning.hpp"

namespace bellows::ui {
namespace {

constexpr int kMaxBatch = 1000;

void pop_last_code_point(std::string& text) {
  while (!text.empty()) {
    const auto byte = static_cast<unsigned char>(text.back());
    text.pop_back();
    if ((byte & 0xC0) != 0x80) break;  // stop after the first byte of a sequence
  }
}

bool parse_number(const std::string& text, double& value) {
  if (text.empty()) return false;
  char* end = nullptr;
  value = std::strtod(text.c_str(), &end);
  return end != nullptr && *end == '\0' && std::isfinite(value);
}

}  // namespace

void ConsoleController::handle_key(int k, double now_s) {
  now_s_ = now_s;
  ++revision_;
  if (k == key::kResize) return;
  if (k == ' ') {  // from every screen and every dialog
    emergency_stop("EMERGENCY STOP (Space)");
    return;
  }
  if (state_.dialog.kind != DialogKind::kNone) {
    handle_dialog_key(k);
    return;
  }
  if (state_.width < kMinWidth || state_.height < kMinHeight) {
    if (k == 'q') perform(Action::kQuit);  // the too-small screen offers Space and q only
    return;
  }
  if (handle_screen_key(k)) return;
  if (const auto action = action_for_key(k)) perform(*action);
}

void ConsoleController::open_dialog(DialogKind kind, std::string title, std::vector<std::string> text, std::string hint,
                                    std::string input) {
  state_.dialog = Dialog{kind, std::move(title), std::move(text), std::move(input), std::move(hint)};
}

bool ConsoleController::handle_dialog_key(int k) {
  Dialog& d = state_.dialog;
  const bool prompt = d.kind == DialogKind::kAskIterations || d.kind == DialogKind::kTrajectoryPath ||
                      d.kind == DialogKind::kEditValue;
  if (k == key::kEscape) {
    state_.dialog = {};
    pending_discard_action_ = nullptr;
    set_status("cancelled");
    return true;
  }
  if (prompt) {
    if (k == key::kEnter) {
      accept_input();
    } else if (k == key::kBackspace) {
      pop_last_code_point(d.input);
    } else if (k >= 0x20 && k < key::kSpecial && d.input.size() < 512) {
      append_utf8(d.input, static_cast<char32_t>(k));
    }
    return true;
  }
  switch (d.kind) {
    case DialogKind::kConfirmArm:
      if (k == 'y' || k == 'Y') {
        state_.dialog = {};
        send_simple(CommandKind::kArm, "arm");
        log(LogSource::kOperator, "arm");
      } else if (k == 'n' || k == 'N') {
        state_.dialog = {};
        set_status("not armed");
      }
      return true;
    case DialogKind::kConfirmDiscard:
      if (k == 'y' || k == 'Y') {
        state_.dialog = {};
        auto action = std::move(pending_discard_action_);
        pending_discard_action_ = nullptr;
        if (action) action();
      } else if (k == 'n' || k == 'N') {
        state_.dialog = {};
        pending_discard_action_ = nullptr;
        set_status("cancelled");
      }
      return true;
    case DialogKind::kConfirmQuit:
      if (k == 's' && state_.sessions_available) {
        state_.dialog = {};
        quit_after_save_ = true;
        start_save();
      } else if (k == 'q' || k == 'y') {
        state_.dialog = {};
        quit_now();
      } else if (k == 'n' || k == 'c') {
        state_.dialog = {};
      }
      return true;
    default:
      return true;
  }
}

void ConsoleController::accept_input() {
  Dialog d = state_.dialog;
  state_.dialog = {};
  switch (d.kind) {
    case DialogKind::kAskIterations: {
      double k = 0;
      if (!parse_number(d.input, k) || k < 1 || k > kMaxBatch || std::floor(k) != k) {
        set_status(format("K must be a whole number from 1 to %d, not '%s'", kMaxBatch, d.input.c_str()), true);
        return;
      }
      if (!availability(Action::kRunIterations, state_).available) {
        set_status("cannot run iterations now: " + availability(Action::kRunIterations, state_).reason, true);
        return;
      }
      state_.run = RunProgress{};
      state_.run.mode = RunProgress::Mode::kBatch;
      state_.run.batch_total = static_cast<int>(k);
      log(LogSource::kOperator, format("run %d iterations (stops by itself after %d rises of the RMS in a row)",
                                       state_.run.batch_total, state_.stop_after_rises));
      step();
      return;
    }
    case DialogKind::kTrajectoryPath: {
      state_.chooser.file_path = d.input;
      preview_selected_trajectory();
      return;
    }
    case DialogKind::kEditValue:
      apply_tuning(state_.tuning.selected, d.input);
      return;
    default:
      return;
  }
}

bool ConsoleController::handle_screen_key(int k) {
  switch (state_.screen) {
    case Screen::kInspector: {
      InspectorView& v = state_.inspector;
      const int trials = static_cast<int>(state_.experiment.trials.size());
      if (trials == 0) return false;
      v.trial = std::clamp(v.trial, 0, trials - 1);
      const int n = state_.experiment.trials[static_cast<std::size_t>(v.trial)].record.learning_samples;
      const int page = std::max(1, n / 10);
      switch (k) {
        case key::kLeft: v.sample = std::max(0, v.sample - 1); return true;
        case key::kRight: v.sample = std::min(n, v.sample + 1); return true;
        case key::kPageUp: v.sample = std::max(0, v.sample - page); return true;
        case key::kPageDown: v.sample = std::min(n, v.sample + page); return true;
        case key::kHome: v.sample = 0; return true;
        case key::kEnd: v.sample = n; return true;
        case key::kUp: v.trial = std::max(0, v.trial - 1); return true;
        case key::kDown: v.trial = std::min(trials - 1, v.trial + 1); return true;
        case 'm':
          v.chosen = v.chosen == v.trial ? -1 : v.trial;
          return true;
        case 'u': {
          const Trial& t = state_.experiment.trials[static_cast<std::size_t>(v.trial)];
          if (state_.run.mode != RunProgress::Mode::kIdle) {
            set_status("not while trials run", true);
            return true;
          }
          state_.experiment.set_next(t.correction_bar, "correction of " + std::to_string(t.iteration));
          log(LogSource::kOperator, format("go back to the correction of iteration %d for the next trial", t.iteration));
          set_status(format("the next trial applies the correction of iteration %d", t.iteration));
          return true;
        }
        default: return false;
      }
    }
    case Screen::kTrajectory: {
      TrajectoryChooser& ch = state_.chooser;
      const int count = static_cast<int>(ch.names.size());
      if (k == key::kUp || k == key::kDown) {
        ch.selected = std::clamp(ch.selected + (k == key::kUp ? -1 : 1), 0, count - 1);
        preview_selected_trajectory();
        return true;
      }
      if (k == key::kEnter) {
        const bool file_entry = ch.selected == count - 1;
        if (file_entry && (!ch.preview || !ch.preview_error.empty() || ch.file_path.empty())) {
          open_dialog(DialogKind::kTrajectoryPath, "Trajectory file", {"A CSV file with the header time_s,angle_deg,",
                      "sampled every " + format("%.3f s", env_.config.timing.sample_s()) + " from t = 0."},
                      "Enter load and preview   Esc cancel", ch.file_path);
          return true;
        }
        if (ch.preview && ch.preview_error.empty()) use_trajectory(ch.preview);
        return true;
      }
      return false;
    }
    case Screen::kTuning:
      if (k == key::kUp || k == key::kDown) {
        state_.tuning.selected = std::clamp(state_.tuning.selected + (k == key::kUp ? -1 : 1), 0, TuningForm::kFields - 1);
        return true;
      }
      if (k == key::kEnter) {
        if (state_.run.mode != RunProgress::Mode::kIdle || state_.engine_state == EngineState::kRunning) {
          set_status("gains and weights change between trials: stop the trials first (x)", true);
        } else if (state_.engine_state == EngineState::kFault) {
          set_status("a fault is latched: reset it (R) before changing gains", true);
        } else {
          const TuningField& f = tuning_fields()[static_cast<std::size_t>(state_.tuning.selected)];
          open_dialog(DialogKind::kEditValue, std::string("Change ") + f.label,
                      {std::string(f.description) + " (" + f.config_key + ")"}, "Enter apply   Esc cancel",
                      format("%g", tuning_value(state_.config, state_.tuning.selected)));
        }
        return true;
      }
      return false;
    case Screen::kSessions: {
      SessionBrowser& b = state_.browser;
      const int count = static_cast<int>(b.sessions.size());
      if ((k == key::kUp || k == key::kDown) && count > 0) {
        b.selected = std::clamp(b.selected + (k == key::kUp ? -1 : 1), 0, count - 1);
        return true;
      }
      if (k == key::kEnter && count > 0) {
        const SessionListing& l = b.sessions[static_cast<std::size_t>(b.selected)];
        if (!l.error.empty()) {
          set_status(l.name + " cannot be opened: " + l.error, true);
        } else if (!availability(Action::kOpen, state_).available) {
          set_status("cannot open now: " + availability(Action::kOpen, state_).reason, true);
        } else {
          const std::string location = l.location;
          confirm_discard("opening " + l.name, [this, location] { start_open(location); });
        }
        return true;
      }
      return false;
    }
    case Screen::kLog: {
      const int count = static_cast<int>(state_.log.entries().size());
      const int page = std::max(1, state_.height - 8);
      int& scroll = state_.log_scroll;
      if (k == key::kUp) scroll = std::min(count - 1, scroll + 1);
      else if (k == key::kDown) scroll = std::max(0, scroll - 1);
      else if (k == key::kPageUp) scroll = std::min(std::max(count - 1, 0), scroll + page);
      else if (k == key::kPageDown) scroll = std::max(0, scroll - page);
      else if (k == key::kEnd) scroll = 0;
      else return false;
      scroll = std::max(0, scroll);
      return true;
    }
    case Screen::kMain:
    case Screen::kHelp:
    case Screen::kFault:
      return false;
  }
  return false;
}

void ConsoleController::perform(Action action) {
  const Availability a = availability(action, state_);
  if (!a.available) {
    set_status(std::string(binding(action).bar_label) + ": " + a.reason, true);
    return;
  }
  switch (action) {
    case Action::kHelp:
      if (state_.screen == Screen::kHelp) {
        state_.screen = state_.previous_screen;
      } else {
        state_.previous_screen = state_.screen;
        state_.screen = Screen::kHelp;
      }
      return;
    case Action::kEmergencyStop:
      emergency_stop("EMERGENCY STOP (Space)");
      return;
    case Action::kArm: {
      const Trajectory& t = *state_.experiment.trajectory;
      open_dialog(DialogKind::kConfirmArm, "Arm the valves?",
                  {"The valves go live: the arm moves to the start of " + t.name,
                   format("(%.1f deg) and holds it with the PID.", t.angle_rad(0) * 180.0 / std::numbers::pi)},
                  "y arm   n or Esc cancel");
      return;
    }
    case Action::kDisarm:
      if (state_.run.mode != RunProgress::Mode::kIdle) state_.run.stop_requested = true;
      send_simple(CommandKind::kDisarm, "disarm");
      log(LogSource::kOperator, "disarm");
      return;
    case Action::kReset:
      send_simple(CommandKind::kReset, "reset");
      log(LogSource::kOperator, format("reset the fault (%s)", fault_name(state_.fault)));
      set_status("fault reset: the valves stay vented (SAFE) until you arm (a)");
      if (state_.screen == Screen::kFault) state_.screen = Screen::kMain;
      return;
    case Action::kTrajectory:
      open_trajectory_chooser();
      return;
    case Action::kRunTrial:
      state_.run = RunProgress{};
      state_.run.mode = RunProgress::Mode::kTrial;
      begin_trial();
      return;
    case Action::kNextIteration:
      state_.run = RunProgress{};
      state_.run.mode = RunProgress::Mode::kStep;
      step();
      return;
    case Action::kRunIterations:
      open_dialog(DialogKind::kAskIterations, "Run K iterations",
                  {"Each iteration learns from the last trial, then runs.",
                   format("x interrupts; it stops by itself when the RMS rises %d times in a row.", state_.stop_after_rises)},
                  "Enter run   Esc cancel", "10");
      return;
    case Action::kStopRun:
      state_.run.stop_requested = true;
      if (state_.engine_state == EngineState::kRunning) send_simple(CommandKind::kAbortTrial, "abort trial");
      log(LogSource::kOperator, "stop the trials");
      set_status("stopping the trials");
      return;
    case Action::kInspector: {
      InspectorView& v = state_.inspector;
      const int trials = static_cast<int>(state_.experiment.trials.size());
      if (v.trial < 0 || v.trial >= trials) v.trial = trials - 1;
      state_.screen = Screen::kInspector;
      return;
    }
    case Action::kTuning: state_.screen = Screen::kTuning; return;
    case Action::kLog:
      state_.log_scroll = 0;
      state_.screen = Screen::kLog;
      return;
    case Action::kFaultView: state_.screen = Screen::kFault; return;
    case Action::kSave: start_save(); return;
    case Action::kOpen:
      state_.screen = Screen::kSessions;
      start_listing();
      return;
    case Action::kQuit:
      if (state_.experiment.unsaved() && !state_.experiment.trials.empty()) {
        const int unsaved = static_cast<int>(state_.experiment.trials.size()) - state_.experiment.saved_trials;
        std::vector<std::string> text = {format("%d iteration%s not saved%s.", unsaved, unsaved == 1 ? " is" : "s are",
                                                state_.experiment.settings_changed ? " and settings changed" : "")};
        if (!state_.sessions_available) text.push_back("Saving is not available: " + state_.sessions_unavailable_reason);
        text.push_back("The valves are vented before the console exits.");
        open_dialog(DialogKind::kConfirmQuit, "Quit?", text,
                    state_.sessions_available ? "s save and quit   q quit without saving   Esc cancel"
                                              : "q quit without saving   Esc cancel");
      } else {
        quit_now();
      }
      return;
    case Action::kHeartbeatDrill:
      state_.heartbeat_drill = true;
      drill_started_s_ = now_s_;
      log(LogSource::kOperator, format("heartbeat drill: heartbeats withheld; the engine must vent within %.1f s",
                                       env_.config.safety.heartbeat_timeout_s));
      return;
    case Action::kMain: state_.screen = Screen::kMain; return;
  }
}

void ConsoleController::open_trajectory_chooser() {
  TrajectoryChooser& ch = state_.chooser;
  ch.names.clear();
  ch.descriptions.clear();
  const std::string current = state_.experiment.trajectory->name;
  ch.selected = -1;
  for (const std::string& name : trajectory_library_names()) {
    if (name == current) ch.selected = static_cast<int>(ch.names.size());
    ch.names.push_back(name);
    ch.descriptions.push_back(trajectory_library_description(name));
  }
  ch.names.push_back("from a file...");
  ch.descriptions.push_back("CSV: time_s,angle_deg");
  if (ch.selected < 0) ch.selected = static_cast<int>(ch.names.size()) - 1;
  state_.screen = Screen::kTrajectory;
  preview_selected_trajectory();
}

void ConsoleController::preview_selected_trajectory() {
  TrajectoryChooser& ch = state_.chooser;
  ch.preview.reset();
  ch.preview_error.clear();
  const bool file_entry = ch.selected == static_cast<int>(ch.names.size()) - 1;
  const std::string what = file_entry ? ch.file_path : ch.names[static_cast<std::size_t>(ch.selected)];
  if (what.empty()) return;
  if (!file_entry && what == state_.experiment.trajectory->name) {
    ch.preview = state_.experiment.trajectory;
    return;
  }
  try {
    ch.preview = std::make_shared<const Trajectory>(env_.load_trajectory(what));
  } catch (const std::exception& error) {
    ch.preview_error = error.what();
  }
}

void ConsoleController::confirm_discard(std::string what, std::function<void()> action) {
  const Experiment& e = state_.experiment;
  if (!e.unsaved() || e.trials.empty()) {
    action();
    return;
  }
  pending_discard_action_ = std::move(action);
  const int unsaved = static_cast<int>(e.trials.size()) - e.saved_trials;
  open_dialog(DialogKind::kConfirmDiscard, "Discard unsaved work?",
              {format("%d iteration%s not saved; %s starts afresh.", unsaved, unsaved == 1 ? " is" : "s are", what.c_str())},
              "y discard   n or Esc cancel");
}

void ConsoleController::use_trajectory(std::shared_ptr<const Trajectory> trajectory) {
  if (state_.engine_state == EngineState::kFault) {
    set_status("a fault is latched: reset it (R) before choosing a trajectory", true);
    return;
  }
  if (state_.run.mode != RunProgress::Mode::kIdle || state_.engine_state == EngineState::kRunning) {
    set_status("not while trials run", true);
    return;
  }
  if (trajectory == state_.experiment.trajectory) {
    state_.screen = Screen::kMain;
    return;
  }
  confirm_discard("the trajectory " + trajectory->name, [this, trajectory] {
    const int old_samples = state_.experiment.samples();
    select_trajectory(trajectory);
    state_.experiment = Experiment::start(trajectory);
    state_.inspector = InspectorView{};
    if (trajectory->learning_samples() != old_samples || !law_) rebuild_law();
    log(LogSource::kOperator, format("trajectory %s (%.1f s, N = %d)", trajectory->name.c_str(), trajectory->duration_s(),
                                     trajectory->learning_samples()));
    set_status("trajectory " + trajectory->name + ": iteration 0 runs with feedback only");
    state_.screen = Screen::kMain;
  });
}

void ConsoleController::apply_tuning(int field, const std::string& text) {
  const TuningField& f = tuning_fields()[static_cast<std::size_t>(field)];
  double value = 0;
  if (!parse_number(text, value)) {
    set_status(std::string(f.label) + ": '" + text + "' is not a number", true);
    return;
  }
  Configuration candidate = state_.config;
  const double old = *f.value(candidate);
  *f.value(candidate) = value;
  try {
    validate_configuration(candidate);
  } catch (const InputError& error) {
    set_status(error.what(), true);
    return;
  }
  if (old == value) return;
  state_.config = candidate;
  state_.experiment.settings_changed = true;
  log(LogSource::kOperator, format("%s changed %g -> %g (%s)", f.label, old, value, f.config_key));
  if (f.learning_weight) {
    rebuild_law();
  } else {
    send_gains();
  }
  set_status(format("%s = %g from the next trial on", f.label, value));
}

void ConsoleController::quit_now() {
  log(LogSource::kOperator, "quit: vent and exit");
  if (valves_live(state_.engine_state)) send_simple(CommandKind::kDisarm, "disarm");
  quit_requested_ = true;
}

}  // namespace bellows::ui
