// The screens' own keys (inspector, trajectory chooser, tuning, sessions, log) and what they do.
#include <algorithm>
#include <cmath>
#include <cstdlib>

#include "engine/base/errors.hpp"
#include "engine/base/units.hpp"
#include "engine/config/learning_law_factory.hpp"
#include "ui/canvas.hpp"
#include "ui/console_controller.hpp"
#include "ui/keys.hpp"
#include "ui/plot_data.hpp"
#include "ui/render_parts.hpp"
#include "ui/text_input.hpp"
#include "ui/tuning.hpp"

namespace bellows::ui {

void ConsoleController::jump_to_error_peak(int step) {
  InspectorView& v = state_.inspector;
  const int trials = static_cast<int>(state_.experiment.trials.size());
  if (trials == 0) return;
  if (state_.screen != Screen::kInspector) {  // from anywhere: the inspector on the newest trial
    v.trial = trials - 1;
    v.peak = -1;
    state_.screen = Screen::kInspector;
  }
  v.trial = std::clamp(v.trial, 0, trials - 1);
  const Trial& t = state_.experiment.trials[static_cast<std::size_t>(v.trial)];
  if (!t.in_memory()) {
    set_status(format("iteration %d is on disk only (the console keeps the newest %d trials in memory)", t.iteration,
                      Experiment::kTrialsKeptInMemory),
               true);
    return;
  }
  const int joint = selected_joint(state_) < t.record.joint_count() ? selected_joint(state_) : 0;
  const std::vector<int> peaks = error_peaks(t.record, joint);
  if (peaks.empty()) {
    set_status(format("iteration %d has no error to jump to", t.iteration), true);
    return;
  }
  const int count = static_cast<int>(peaks.size());
  v.peak = v.peak < 0 ? (step > 0 ? 0 : count - 1) : ((v.peak + step) % count + count) % count;
  v.sample = peaks[static_cast<std::size_t>(v.peak)];
  const TrialSamples& samples = t.record.joint_samples(joint);
  set_status(format("iteration %d: |error| peak %d of %d, %.2f deg at %.2f s (sample %d); e next, E back", t.iteration,
                    v.peak + 1, count, std::abs(samples.error_rad(v.sample)) * kDegPerRad,
                    t.record.sample_time_s(v.sample), v.sample));
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
        case key::kLeft:
          v.sample = std::max(0, v.sample - 1);
          return true;
        case key::kRight:
          v.sample = std::min(n, v.sample + 1);
          return true;
        case key::kPageUp:
          v.sample = std::max(0, v.sample - page);
          return true;
        case key::kPageDown:
          v.sample = std::min(n, v.sample + page);
          return true;
        case key::kHome:
          v.sample = 0;
          return true;
        case key::kEnd:
          v.sample = n;
          return true;
        case key::kUp:
          v.trial = std::max(0, v.trial - 1);
          v.peak = -1;
          return true;
        case key::kDown:
          v.trial = std::min(trials - 1, v.trial + 1);
          v.peak = -1;
          return true;
        case 'E':
          jump_to_error_peak(-1);
          return true;
        case 'm':
          v.chosen = v.chosen == v.trial ? -1 : v.trial;
          return true;
        case 'u': {
          const Trial& t = state_.experiment.trials[static_cast<std::size_t>(v.trial)];
          if (state_.run.mode != RunProgress::Mode::kIdle) {
            set_status("not while trials run", true);
            return true;
          }
          if (!t.in_memory()) {
            set_status(format("iteration %d is on disk only (the console keeps the newest %d trials in memory)",
                              t.iteration, Experiment::kTrialsKeptInMemory),
                       true);
            return true;
          }
          state_.experiment.set_next(t.correction_bar, "correction of " + std::to_string(t.iteration),
                                     t.summary.learned_with);
          log(LogSource::kOperator,
              format("go back to the correction of iteration %d for the next trial", t.iteration));
          set_status(format("the next trial applies the correction of iteration %d", t.iteration));
          return true;
        }
        default:
          return false;
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
          open_dialog(DialogKind::kTrajectoryPath, "Trajectory file",
                      {"A CSV file with the header time_s,angle_deg,",
                       "sampled every " + format("%.3f s", env_.config.timing.sample_s()) + " from t = 0."},
                      "Enter load and preview   Esc cancel", ch.file_path);
          return true;
        }
        if (ch.preview && ch.preview_error.empty()) use_trajectory(ch.preview);
        return true;
      }
      return false;
    }
    case Screen::kTuning: {
      if (k == key::kUp || k == key::kDown) {
        state_.tuning.selected =
            std::clamp(state_.tuning.selected + (k == key::kUp ? -1 : 1), 0, TuningForm::kRows - 1);
        return true;
      }
      const bool on_law = state_.tuning.selected == TuningForm::kLawRow;
      const bool choose_law = on_law && (k == key::kEnter || k == key::kLeft || k == key::kRight);
      if (k != key::kEnter && !choose_law) return false;
      if (state_.run.mode != RunProgress::Mode::kIdle || state_.engine_state == EngineState::kRunning) {
        set_status("gains, law and weights change between trials: stop the trials first (x)", true);
      } else if (state_.engine_state == EngineState::kFault) {
        set_status("a fault is latched: reset it (R) before changing gains", true);
      } else if (choose_law) {
        choose_law_step(k == key::kLeft ? -1 : 1);
      } else {
        const int field = TuningForm::field_of(state_.tuning.selected);
        const TuningField& f = tuning_fields()[static_cast<std::size_t>(field)];
        open_dialog(DialogKind::kEditValue, std::string("Change ") + f.label,
                    {std::string(f.description) + " (" + f.config_key + ")"}, "Enter apply   Esc cancel",
                    format("%g", tuning_value(state_.config, field)));
      }
      return true;
    }
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
        } else if (!l.refusal.empty()) {
          set_status(l.name + " cannot be opened here: " + l.refusal + " (bellows console --device " + l.device +
                         " --session " + l.location + ")",
                     true);
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
      const int page = std::max(1, state_.height - 8);
      // At the top the oldest entry is on the first row and the page is full (no page of blanks).
      const int top = detail::log_top_scroll(state_);
      int& scroll = state_.log_scroll;
      if (k == key::kUp) scroll += 1;
      else if (k == key::kDown) scroll -= 1;
      else if (k == key::kPageUp) scroll += page;
      else if (k == key::kPageDown) scroll -= page;
      else if (k == key::kHome) scroll = top;
      else if (k == key::kEnd) scroll = 0;
      else return false;
      scroll = std::clamp(scroll, 0, top);
      return true;
    }
    case Screen::kRig:
      return handle_rig_key(k);
    case Screen::kHelp: {
      if (k == 'q' || k == key::kEscape) {  // as in less, man and htop: back where help was opened
        state_.screen = state_.previous_screen;
        return true;
      }
      const int page = std::max(1, state_.height - 6);  // the help's inner height
      const int last = std::max(0, detail::help_line_count(state_) - page);
      int& top = state_.help_scroll;
      if (k == key::kUp) top -= 1;
      else if (k == key::kDown) top += 1;
      else if (k == key::kPageUp) top -= page;
      else if (k == key::kPageDown) top += page;
      else if (k == key::kHome) top = 0;
      else if (k == key::kEnd) top = last;
      else return false;
      top = std::clamp(top, 0, last);
      return true;
    }
    case Screen::kMain:
    case Screen::kFault:
      return false;
  }
  return false;
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
  if (file_entry) {  // read once, off the UI thread, when its path was given
    ch.preview = ch.file_trajectory;
    return;
  }
  try {
    ch.preview = std::make_shared<const Trajectory>(env_.load_trajectory(what));
  } catch (const std::exception& error) {
    ch.preview_error = error.what();
  }
}

void ConsoleController::confirm_discard(const std::string& what, std::function<void()> action) {
  const Experiment& e = state_.experiment;
  if (!e.unsaved() || e.trials.empty()) {
    action();
    return;
  }
  pending_discard_action_ = std::move(action);
  const int unsaved = static_cast<int>(e.trials.size()) - e.saved_trials;
  open_dialog(
      DialogKind::kConfirmDiscard, "Discard unsaved work?",
      {format("%d iteration%s not saved; %s starts afresh.", unsaved, unsaved == 1 ? " is" : "s are", what.c_str())},
      "y discard   n or Esc cancel");
}

void ConsoleController::use_trajectory(const std::shared_ptr<const Trajectory>& trajectory) {
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
  // Armed, the engine holds the new trajectory's start at once: the arm moves. The arm question
  // promised the old start, so a new one is asked for (naming both) before anything changes.
  const std::shared_ptr<const Trajectory> old = state_.experiment.trajectory;
  if (valves_live(state_.engine_state) && old != nullptr && old->joints() == trajectory->joints()) {
    double largest_deg = 0.0;
    std::string moves;
    for (int j = 0; j < trajectory->joints(); ++j) {
      const double from_deg = old->joint(j)(0) * kDegPerRad;
      const double to_deg = trajectory->joint(j)(0) * kDegPerRad;
      largest_deg = std::max(largest_deg, std::abs(to_deg - from_deg));
      moves += format("%s%.1f -> %.1f deg", j == 0 ? "" : ", ", from_deg, to_deg);
    }
    // Within the tolerance a trial's hold counts as at its start ([timing] settle_tolerance_deg): no move.
    if (largest_deg > state_.config.timing.settle_tolerance_deg) {
      pending_move_action_ = [this, trajectory] { choose_trajectory(trajectory); };
      open_dialog(DialogKind::kConfirmStartMove, "Move the arm to the new start?",
                  {"The valves are live: the arm moves at once to the start of " + trajectory->name,
                   "and holds it with the PID (" + moves + ")."},
                  "y move   n or Esc cancel");
      return;
    }
  }
  choose_trajectory(trajectory);
}

void ConsoleController::choose_trajectory(const std::shared_ptr<const Trajectory>& trajectory) {
  confirm_discard("the trajectory " + trajectory->name, [this, trajectory] {
    const int old_samples = state_.experiment.samples();
    select_trajectory(trajectory);
    remember_taught();
    state_.experiment = Experiment::start(trajectory);
    ++experiment_serial_;
    state_.inspector = InspectorView{};
    if (trajectory->learning_samples() != old_samples || !law_) rebuild_law();
    log(LogSource::kOperator, format("trajectory %s (%.1f s, N = %d)", trajectory->name.c_str(),
                                     trajectory->duration_s(), trajectory->learning_samples()));
    set_status("trajectory " + trajectory->name + ": iteration 0 runs with feedback only");
    state_.screen = Screen::kMain;
    offer_transfer();
  });
}

void ConsoleController::choose_law_step(int step) {
  const std::vector<std::string> names = learning_law_names();
  const auto current = std::find(names.begin(), names.end(), state_.config.ilc.law);
  const auto count = static_cast<long>(names.size());
  const long at = current == names.end() ? 0 : (current - names.begin() + step + count) % count;
  Configuration candidate = state_.config;
  const std::string old = candidate.ilc.law;
  candidate.ilc.law = names[static_cast<std::size_t>(at)];
  try {
    validate_configuration(candidate);
  } catch (const InputError& error) {
    set_status(std::string("law ") + candidate.ilc.law + ": " + error.what(), true);
    return;
  }
  state_.config = candidate;
  state_.experiment.settings_changed = true;
  log(LogSource::kOperator, format("law changed %s -> %s ([ilc] law)", old.c_str(), candidate.ilc.law.c_str()));
  rebuild_law();
  set_status("law " + candidate.ilc.law +
             " from the next learning step on: " + learning_law_description(candidate.ilc.law));
}

std::string ConsoleController::apply_tuning(int field, const std::string& text) {
  const TuningField& f = tuning_fields()[static_cast<std::size_t>(field)];
  double value = 0;
  switch (parse_number(trim(text), value)) {
    case NumberParse::kNumber:
      break;
    case NumberParse::kNotANumber:
      return std::string(f.label) + ": '" + text + "' is not a number";
    case NumberParse::kOutOfRange:
      return std::string(f.label) + ": '" + text + "' is out of range";
  }
  Configuration candidate = state_.config;
  const double old = *f.value(candidate);
  *f.value(candidate) = value;
  try {
    validate_configuration(candidate);
  } catch (const InputError& error) {
    return error.what();
  }
  if (old == value) {
    set_status(format("%s stays %g", f.label, value));
    return {};
  }
  state_.config = candidate;
  state_.experiment.settings_changed = true;
  log(LogSource::kOperator, format("%s changed %g -> %g (%s)", f.label, old, value, f.config_key));
  if (f.learning_weight) {
    rebuild_law();
  } else {
    send_gains();
  }
  set_status(format("%s = %g from the next trial on", f.label, value));
  return {};
}

}  // namespace bellows::ui
