// The operator's side of the controller: keys, dialogs and the global commands.
#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <numbers>
#include <utility>

#include "engine/base/errors.hpp"
#include "ui/console_controller.hpp"
#include "ui/joint_view.hpp"
#include "ui/keys.hpp"
#include "ui/render.hpp"
#include "ui/text_input.hpp"
#include "ui/tuning.hpp"

namespace bellows::ui {
namespace {

constexpr int kMaxBatch = 1000;
constexpr std::size_t kMaxInputBytes = 512;

/// A dialog that takes typed text (every other one takes answer keys).
bool is_prompt(DialogKind kind) {
  return kind == DialogKind::kAskIterations || kind == DialogKind::kTrajectoryPath || kind == DialogKind::kEditValue ||
         kind == DialogKind::kSessionName;
}

}  // namespace

void ConsoleController::handle_key(int k, double now_s) {
  now_s_ = now_s;
  ++revision_;
  // What a key says belongs to the screen the key leaves the operator on (status_screen).
  struct StatusFollowsTheKey {
    ConsoleController& c;
    std::uint64_t serial;
    ~StatusFollowsTheKey() {
      if (c.status_serial_ != serial) c.state_.status_screen = c.state_.screen;
    }
  } follows{*this, status_serial_};
  if (k == key::kResize) return;
  if (k == key::kRepaint) {  // from every screen and every dialog: the terminal redraws every cell
    ++repaints_;
    return;
  }
  if (k == ' ') {  // from every screen and every dialog
    emergency_stop("EMERGENCY STOP (Space)");
    return;
  }
  if (state_.dialog.kind != DialogKind::kNone) {
    handle_dialog_key(k);
    return;
  }
  if (state_.width < kMinWidth || state_.height < kMinHeight) {
    if (k == 'q') {
      perform(Action::kQuit);  // the too-small screen offers Space and q only
    } else {
      set_status(key_name(k) + ": the window is too small; enlarge it (Space stops, q quits)", true);
    }
    return;
  }
  if (handle_screen_key(k) || handle_transfer_key(k)) return;
  if (const auto action = action_for_key(k)) {
    perform(*action);
  } else {
    set_status(key_name(k) + " does nothing here; ? lists every key", true);
  }
}

void ConsoleController::open_dialog(DialogKind kind, std::string title, std::vector<std::string> text, std::string hint,
                                    std::string input) {
  state_.dialog = Dialog{kind, std::move(title), std::move(text), std::move(input), std::move(hint), {}};
}

void ConsoleController::interrupt_dialog(const std::string& what) {
  const DialogKind kind = state_.dialog.kind;
  if (kind == DialogKind::kNone || kind == DialogKind::kInterrupted) return;
  pending_discard_action_ = nullptr;
  pending_move_action_ = nullptr;
  const std::string closed = state_.dialog.title;
  open_dialog(DialogKind::kInterrupted, "Closed by " + what,
              {"'" + closed + "' was closed by " + what + ": nothing typed into it was taken.",
               "What you type now does nothing until Enter or Esc."},
              "Enter or Esc: continue");
}

// Every key of an open dialog ends here and nowhere else: a prompt or a question keeps the focus
// until it takes an answer (Enter with a valid one, or a listed answer key) or Esc; nothing typed
// into it reaches the command table.
bool ConsoleController::handle_dialog_key(int k) {
  Dialog& d = state_.dialog;
  if (k == key::kEscape ||
      (k == 'q' && !is_prompt(d.kind) && d.kind != DialogKind::kConfirmQuit && d.kind != DialogKind::kInterrupted)) {
    state_.dialog = {};  // back to the screen beneath it
    pending_discard_action_ = nullptr;
    pending_move_action_ = nullptr;
    set_status("cancelled");
    return true;
  }
  if (is_prompt(d.kind)) {
    if (k == key::kEnter) {
      // The one place a prompt closes on Enter: only when its answer is taken.
      PromptAnswer answer = judge_input();
      if (!answer.refusal.empty()) {
        reject_input(std::move(answer.refusal));
        return true;
      }
      state_.dialog = {};
      if (answer.then) answer.then();
    } else if (k == key::kBackspace) {
      pop_last_code_point(d.input);
      d.error.clear();
    } else if (k == key::kClearLine) {
      d.input.clear();
      d.error.clear();
    } else if (k >= 0x20 && k < key::kSpecial) {
      if (d.input.size() < kMaxInputBytes) {
        append_utf8(d.input, static_cast<char32_t>(k));
        d.error.clear();
      } else {
        d.error = format("at most %zu characters", kMaxInputBytes);
      }
    } else {
      d.error = key_name(k) + " does nothing here: type, then " + d.hint;
    }
    return true;
  }
  switch (d.kind) {
    case DialogKind::kInterrupted:
      if (k == key::kEnter) {
        state_.dialog = {};
      } else {
        not_an_answer(k);
      }
      return true;
    case DialogKind::kConfirmStartMove:
      answer_pending(k, pending_move_action_, "trajectory unchanged: the arm holds where it was");
      return true;
    case DialogKind::kConfirmArm:
      answer_yes_no(
          k, [this] { arm(); }, "not armed");
      return true;
    case DialogKind::kConfirmZeroAngle:
      answer_yes_no(
          k, [this] { zero_angle(); }, "angle zero unchanged");
      return true;
    case DialogKind::kConfirmValveTest:
      answer_yes_no(
          k, [this] { start_valve_test(); }, "valve test cancelled: no valve opened");
      return true;
    case DialogKind::kConfirmDiscard:
      answer_pending(k, pending_discard_action_, "cancelled");
      return true;
    case DialogKind::kConfirmQuit:
      if (k == 's' && state_.sessions_available && autosave_failed_) {  // the autosave failed: try once more, then quit
        state_.dialog = {};
        quit_after_save_ = true;
        autosave_failed_ = false;
        start_save();
      } else if (k == 'q' || k == 'y' || k == 'Y') {
        state_.dialog = {};
        quit_when_saved();
      } else if (k == 'n' || k == 'N' || k == 'c') {
        state_.dialog = {};
        set_status("cancelled: the console goes on");
      } else if (k == 's') {
        d.error = state_.sessions_available ? "nothing to save again: Esc, or q to quit"
                                            : "cannot save: " + state_.sessions_unavailable_reason;
      } else {
        not_an_answer(k);
      }
      return true;
    default:
      return true;
  }
}

void ConsoleController::arm() {
  if (std::exchange(arm_where_saved_pending_, false) && env_.arm_where_saved) {
    std::string why_not;
    try {
      why_not = env_.arm_where_saved();
    } catch (const std::exception& error) {
      why_not = error.what();
    }
    if (why_not.empty()) {
      log(LogSource::kOperator,
          "arm where the session stopped (the engine, the arm and the clock as run --resume puts them)");
      return;
    }
    log(LogSource::kSession, "arming afresh, not where the session stopped: " + why_not);
  }
  if (send_simple(CommandKind::kArm, "arm")) log(LogSource::kOperator, "arm");
}

bool ConsoleController::answer_yes_no(int k, const std::function<void()>& on_yes, const char* status_on_no) {
  if (k == 'y' || k == 'Y') {
    state_.dialog = {};
    on_yes();
  } else if (k == 'n' || k == 'N') {
    state_.dialog = {};
    set_status(status_on_no);
  } else {
    not_an_answer(k);
    return false;  // still open
  }
  return true;
}

void ConsoleController::answer_pending(int k, std::function<void()>& pending, const char* status_on_no) {
  // Taken out before the answer: a "no" drops it, a "yes" runs it once (and may ask anew), any other
  // key leaves it waiting.
  auto action = std::move(pending);
  pending = nullptr;
  if (!answer_yes_no(
          k,
          [&action] {
            if (action) action();
          },
          status_on_no))
    pending = std::move(action);
}

void ConsoleController::not_an_answer(int k) {
  state_.dialog.error = key_name(k) + " is not an answer here: " + state_.dialog.hint;
}

void ConsoleController::reject_input(std::string why) {
  state_.dialog.error = why;  // the dialog stays open with what was typed
  set_status(std::move(why), true);
}

PromptAnswer ConsoleController::judge_input() {
  const Dialog& d = state_.dialog;
  switch (d.kind) {
    case DialogKind::kAskIterations: {
      double k = 0;
      const NumberParse parsed = parse_number(trim(d.input), k);
      if (parsed != NumberParse::kNumber || k < 1 || k > kMaxBatch || std::floor(k) != k) {
        return {format("K must be a whole number from 1 to %d, not '", kMaxBatch) + d.input + "'" +
                    (parsed == NumberParse::kOutOfRange ? " (out of range)" : ""),
                {}};
      }
      if (const Availability a = availability(Action::kRunIterations, state_); !a.available) {
        return {"cannot run iterations now: " + a.reason, {}};
      }
      return {{}, [this, k] {
                state_.run = RunProgress{};
                state_.run.mode = RunProgress::Mode::kBatch;
                state_.run.batch_first = state_.experiment.next_iteration();
                state_.run.batch_total = trials_for_iterations(static_cast<int>(k), !state_.experiment.trials.empty());
                log(LogSource::kOperator,
                    format("run iterations %s (stops by itself after %d rises of the RMS in a row)",
                           batch_span(state_.run).c_str(), state_.stop_after_rises));
                step();
              }};
    }
    case DialogKind::kTrajectoryPath: {
      const std::string path = expand_home(trim(d.input));
      if (path.empty()) return {"type the path of a CSV file (time_s,angle_deg), or Esc", {}};
      // Read on a worker: the prompt stays open, and poll_trajectory_load() takes the answer or says why not.
      if (trajectory_load_.busy()) return {"still reading " + trajectory_load_path_ + " (Esc leaves it)", {}};
      trajectory_load_path_ = path;
      trajectory_load_.start(
          [load = env_.load_trajectory, path] { return std::make_shared<const Trajectory>(load(path)); });
      return {"reading " + path + " ...", {}};
    }
    case DialogKind::kSessionName: {
      const std::string name(trim(d.input));
      if (name.empty()) return {"type a name (letters, digits, - _ .), or Esc", {}};
      if (rename_task_.busy() || save_task_.busy()) return {"saving: Enter again in a moment (or Esc)", {}};
      if (std::string why = env_.sessions->name_refusal(state_.experiment.session_location, name); !why.empty()) {
        return {std::move(why), {}};
      }
      return {{}, [this, name] { start_rename(name); }};
    }
    case DialogKind::kEditValue: {
      std::string why = apply_tuning(TuningForm::field_of(state_.tuning.selected), d.input);
      return {std::move(why), {}};  // applied when empty
    }
    default:
      return {};
  }
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
        state_.help_scroll = 0;
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
                   format("(%.1f deg) and holds it with the PID.", t.joint(0)(0) * 180.0 / std::numbers::pi)},
                  "y arm   n or Esc cancel");
      return;
    }
    case Action::kDisarm:
      if (state_.run.mode != RunProgress::Mode::kIdle) state_.run.stop_requested = true;
      if (!send_simple(CommandKind::kDisarm, "disarm")) {
        emergency_stop("disarm not sent (the command queue is full): emergency stop instead");
        return;
      }
      log(LogSource::kOperator, "disarm");
      return;
    case Action::kReset:
      if (!send_simple(CommandKind::kReset, "reset")) return;  // said by send(); the fault stays latched
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
      begin_trial_when_saved();
      return;
    case Action::kNextIteration:
      state_.run = RunProgress{};
      state_.run.mode = RunProgress::Mode::kStep;
      step();
      return;
    case Action::kRunIterations:
      open_dialog(
          DialogKind::kAskIterations, "Run K iterations",
          {"Each iteration learns from the last trial, then runs;",
           "with no trial yet, iteration 0 (feedback only) runs first.",
           format("x interrupts; it stops by itself when the RMS rises %d times in a row.", state_.stop_after_rises)},
          "Enter run   Esc cancel", "10");
      return;
    case Action::kStopRun:
      state_.run.stop_requested = true;
      if (state_.engine_state == EngineState::kRunning && !send_simple(CommandKind::kAbortTrial, "abort trial")) {
        set_status("abort not sent (the command queue is full): the trial ends by itself, or Space stops", true);
        return;
      }
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
    case Action::kWorstError:
      jump_to_error_peak(+1);
      return;
    case Action::kRmsScale:
      state_.rms_log_scale = !state_.rms_log_scale;
      set_status(state_.rms_log_scale ? "the RMS plot on a log scale (L: linear)"
                                      : "the RMS plot on a linear scale (L: log)");
      return;
    case Action::kTuning:
      state_.screen = Screen::kTuning;
      return;
    case Action::kLog:
      state_.log_scroll = 0;
      state_.screen = Screen::kLog;
      return;
    case Action::kFaultView:
      state_.screen = Screen::kFault;
      return;
    case Action::kSave: {
      const std::string& location = state_.experiment.session_location;
      const std::string current = location.substr(location.find_last_of('/') + 1);
      open_dialog(DialogKind::kSessionName, "Name this session",
                  {"The session is saved as you go, in", location, "A name renames it in the data directory."},
                  "Enter rename   Esc cancel", current);
      return;
    }
    case Action::kRig:
      state_.screen = Screen::kRig;
      return;
    case Action::kFigures:
      start_figures();
      return;
    case Action::kOpen:
      state_.screen = Screen::kSessions;
      start_listing();
      return;
    case Action::kQuit: {
      // kQuitRule (ui/key_map.hpp), the one rule of when quitting asks.
      const Experiment& e = state_.experiment;
      std::vector<std::string> text;
      if (valves_live(state_.engine_state) || state_.run.mode != RunProgress::Mode::kIdle) {
        text.push_back(state_.engine_state == EngineState::kRunning ? "A trial is running with the valves live."
                                                                    : "The valves are live (ARMED).");
      }
      const int unsaved_faults = static_cast<int>(e.faults.size()) - e.saved_faults;
      if (saves_settled() && e.unsaved() && (!e.trials.empty() || unsaved_faults > 0)) {
        text.push_back(e.unsaved_sentence());
        if (!state_.sessions_available)
          text.push_back("Saving is not available: " + state_.sessions_unavailable_reason);
      }
      if (text.empty()) {
        quit_when_saved();
        return;
      }
      text.push_back("Quitting vents the valves before the console exits; the engine goes on until you answer.");
      const bool retry = state_.sessions_available && autosave_failed_;
      open_dialog(
          DialogKind::kConfirmQuit, "Quit?", text,
          retry ? "s save and quit   q or y quit without saving   n or Esc stay" : "q or y quit   n or Esc stay");
      return;
    }
    case Action::kHeartbeatDrill:
      state_.heartbeat_drill = true;
      drill_started_s_ = now_s_;
      log(LogSource::kOperator, format("heartbeat drill: heartbeats withheld; the engine must vent within %.1f s",
                                       env_.config.safety.heartbeat_timeout_s));
      return;
    case Action::kJoint: {
      const int joints = state_.experiment.joints();
      state_.joint = (std::clamp(state_.joint, 0, joints - 1) + 1) % joints;
      export_strip();
      set_status("showing " + joint_label(joints, state_.joint) + " (j: the next joint)");
      return;
    }
    case Action::kMain:
      state_.screen = Screen::kMain;
      return;
  }
}

void ConsoleController::quit_when_saved() {
  if (!saves_settled()) {
    quit_after_save_ = true;  // the autosave in progress (or about to start) first, then quit
    set_status("finishing the save, then quitting");
    autosave();
    return;
  }
  quit_now();
}

void ConsoleController::quit_now() {
  log(LogSource::kOperator, "quit: vent and exit");
  if (valves_live(state_.engine_state) && !send_simple(CommandKind::kDisarm, "disarm")) {
    env_.core->request_emergency_stop();  // the queue is full: vent through the latch instead
  }
  quit_requested_ = true;
}

}  // namespace bellows::ui
