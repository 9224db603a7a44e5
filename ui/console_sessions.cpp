// Saving and opening sessions through the SessionGateway, on background tasks.
#include <algorithm>

#include "engine/base/errors.hpp"
#include "ui/canvas.hpp"
#include "ui/console_controller.hpp"

namespace bellows::ui {

bool ConsoleController::saves_settled() const {
  if (save_task_.busy() || rename_task_.busy()) return false;
  const Experiment& e = state_.experiment;
  const bool worth_a_session = !e.trials.empty() || !e.faults.empty() || !e.session_location.empty();
  return !state_.sessions_available || autosave_failed_ || !e.unsaved() || !worth_a_session;
}

void ConsoleController::autosave() {
  const Experiment& e = state_.experiment;
  // A session is created with the first trial or black box, not by merely looking around.
  const bool worth_a_session = !e.trials.empty() || !e.faults.empty() || !e.session_location.empty();
  if (!state_.sessions_available || save_task_.busy() || rename_task_.busy() || autosave_failed_ || !e.unsaved() ||
      !worth_a_session) {
    return;
  }
  start_save();
}

void ConsoleController::start_save() {
  if (!state_.sessions_available) {
    set_status("saving is not available: " + state_.sessions_unavailable_reason, true);
    quit_after_save_ = false;
    return;
  }
  if (save_task_.busy()) return;  // the completion looks again
  // Only what the save needs: the unsaved trials and the last saved one (its next correction may
  // have changed), never the whole history.
  const Experiment& e = state_.experiment;
  const int trials = static_cast<int>(e.trials.size());
  const int first = e.session_location.empty() ? 0 : std::max(0, std::min(e.saved_trials, trials) - 1);
  SessionSnapshot snapshot;
  snapshot.config = state_.config;
  snapshot.experiment.trajectory = e.trajectory;
  snapshot.experiment.trials.assign(e.trials.begin() + first, e.trials.end());
  snapshot.experiment.next_correction_bar = e.next_correction_bar;
  snapshot.experiment.next_unsaved = e.next_unsaved;
  snapshot.experiment.next_origin = e.next_origin;
  snapshot.experiment.next_tried = e.next_tried;
  snapshot.experiment.saved_trials = e.saved_trials;
  snapshot.experiment.session_location = e.session_location;
  snapshot.experiment.saved_events = e.saved_events;
  snapshot.experiment.settings_changed = e.settings_changed;
  snapshot.experiment.faults = e.faults;                      // saved ones hold no ticks (released)
  snapshot.experiment.first_correction = e.first_correction;  // a new session records it
  snapshot.first_trial = first;
  const std::size_t new_events =
      std::min(state_.log.entries().size(), state_.log.total() - std::min(e.saved_events, state_.log.total()));
  const bool all_events = e.session_location.empty();
  snapshot.events.assign(
      all_events ? state_.log.entries().begin() : state_.log.entries().end() - static_cast<long>(new_events),
      state_.log.entries().end());
  snapshot.events_total = state_.log.total();
  snapshot.device_name = env_.device_name;
  snapshot.seed = env_.seed;
  saving_trials_ = trials;
  saving_faults_ = static_cast<int>(e.faults.size());
  saving_events_ = state_.log.total();
  saving_settings_changed_ = e.settings_changed;
  saving_next_revision_ = e.next_revision;
  saving_experiment_serial_ = experiment_serial_;
  save_task_.start([gateway = env_.sessions, snapshot = std::move(snapshot)] { return gateway->save(snapshot); });
}

void ConsoleController::start_figures() {
  if (!env_.write_figures) {
    set_status("figures are not available in this console", true);
    return;
  }
  if (figure_task_.busy() || figures_after_save_ > 0) {
    set_status("already writing figures");
    return;
  }
  // Drawn from the saved session's files, as `bellows sessions plot` draws them: memory holds only
  // the newest trials. Trials not saved yet are saved first.
  if (!state_.sessions_available) {
    set_status(
        "figures are drawn from the saved session, and saving is not available: " + state_.sessions_unavailable_reason,
        true);
    return;
  }
  if (autosave_failed_) {
    set_status("figures are drawn from the saved session, and saving failed: s saves again", true);
    return;
  }
  figures_after_save_ = static_cast<int>(state_.experiment.trials.size());
  log(LogSource::kSession, format("writing figures of %d iterations", figures_after_save_));
  autosave();
  if (!save_task_.busy() && !rename_task_.busy() && state_.experiment.saved_trials >= figures_after_save_)
    launch_figures();
}

void ConsoleController::launch_figures() {
  const int iterations = figures_after_save_;
  figures_after_save_ = 0;
  figure_task_.start([write = env_.write_figures, location = state_.experiment.session_location, iterations] {
    return write(location, iterations);
  });
}

void ConsoleController::start_rename(const std::string& name) {
  if (rename_task_.busy() || save_task_.busy()) {
    set_status("saving: name the session again in a moment", true);
    return;
  }
  log(LogSource::kSession, "name the session " + name);
  rename_task_.start([gateway = env_.sessions, name] { return gateway->rename(name); });
}

void ConsoleController::start_listing() {
  if (list_task_.busy()) return;
  state_.browser.loading = true;
  state_.browser.error.clear();
  list_task_.start([gateway = env_.sessions] { return gateway->list(); });
}

void ConsoleController::start_open(const std::string& location) {
  if (open_task_.busy()) return;
  state_.learner_busy = true;
  state_.learner_task = "opening";
  log(LogSource::kSession, "opening " + location);
  open_task_.start([gateway = env_.sessions, location] { return gateway->open(location); });
}

void ConsoleController::poll_session_tasks() {
  if (save_task_.ready() && saving_experiment_serial_ != experiment_serial_) {
    // The experiment the operator left (its trials discarded, or a session opened): its save is its
    // own; the current experiment's location and counts stay as they are (else its trials would be
    // appended to the old session, of another trajectory).
    try {
      log(LogSource::kSession, "the last save of the experiment left behind finished: " + save_task_.take());
    } catch (const std::exception& error) {
      log(LogSource::kSession, std::string("the last save of the experiment left behind failed: ") + error.what(),
          true);
    }
    ++revision_;
    autosave();
  } else if (save_task_.ready()) {
    try {
      const std::string location = save_task_.take();
      Experiment& e = state_.experiment;
      const bool first_save = e.session_location != location;
      e.session_location = location;
      e.saved_trials = saving_trials_;
      e.saved_faults = saving_faults_;
      e.saved_events = saving_events_;
      // Settings or a correction changed while saving stay unsaved (the next autosave takes them).
      if (saving_settings_changed_ == e.settings_changed) e.settings_changed = false;
      if (saving_next_revision_ == e.next_revision) e.next_unsaved = false;
      e.release_saved_history();  // on disk now: memory keeps only the newest trials
      if (first_save) {
        log(LogSource::kSession, "saving as it goes to " + location);
        // A background note: it must not hide a warning the operator has not read yet.
        if (!state_.status_important) set_status("this session is saved as it goes: " + location);
      }
    } catch (const std::exception& error) {
      autosave_failed_ = true;  // no retry loop: the operator decides (quit asks, s retries)
      begin_after_save_ = false;
      // Which trials are not on disk (they stay in memory, none released), and how to retry.
      const std::string unsaved = state_.experiment.unsaved_sentence();
      log(LogSource::kSession, std::string("save failed: ") + error.what() + "; " + unsaved, true);
      set_status(std::string("save failed: ") + error.what() + "; " + unsaved +
                     " Kept in memory; the next trial (or s when quitting) retries the save",
                 true);
      if (state_.run.mode != RunProgress::Mode::kIdle) end_run("stopped: the session cannot be saved", true);
      if (figures_after_save_ > 0) log(LogSource::kSession, "figures not written: the session is not saved", true);
      figures_after_save_ = 0;
    }
    ++revision_;
    if (figures_after_save_ > 0 && state_.experiment.saved_trials >= figures_after_save_) launch_figures();
    autosave();  // what changed meanwhile
    if (!save_task_.busy() && !state_.experiment.unsaved()) {
      if (begin_after_save_) {
        begin_after_save_ = false;
        // x (or quitting) while the trial waited for the save: it does not begin.
        if (state_.run.stop_requested || quit_after_save_) {
          end_run("stopped: the trial that waited for the save did not begin", false);
        } else {
          begin_trial();
        }
      }
      if (quit_after_save_) {
        quit_after_save_ = false;
        quit_now();
      }
    } else if (autosave_failed_ && quit_after_save_) {
      quit_after_save_ = false;
      perform(Action::kQuit);  // asks: quit without saving?
    }
  }
  if (rename_task_.ready()) {
    try {
      const std::string location = rename_task_.take();
      state_.experiment.session_location = location;
      log(LogSource::kSession, "the session is now " + location);
      set_status("named: " + location);
    } catch (const std::exception& error) {
      log(LogSource::kSession, std::string("naming failed: ") + error.what(), true);
      set_status(std::string("naming failed: ") + error.what(), true);
    }
    ++revision_;
    if (figures_after_save_ > 0 && !save_task_.busy() && state_.experiment.saved_trials >= figures_after_save_)
      launch_figures();
  }
  if (figure_task_.ready()) {
    try {
      const std::string folder = figure_task_.take();
      log(LogSource::kSession, "figures written to " + folder);
      set_status("figures: " + folder);
    } catch (const std::exception& error) {
      log(LogSource::kSession, std::string("figures failed: ") + error.what(), true);
      set_status(std::string("figures failed: ") + error.what(), true);
    }
    ++revision_;
  }
  if (list_task_.ready()) {
    state_.browser.loading = false;
    try {
      state_.browser.sessions = list_task_.take();
      // Newest first is what an operator looks for.
      std::reverse(state_.browser.sessions.begin(), state_.browser.sessions.end());
      for (SessionListing& l : state_.browser.sessions) l.refusal = drive_refusal(l, env_.device_name);
      state_.browser.selected = 0;
    } catch (const std::exception& error) {
      state_.browser.sessions.clear();
      state_.browser.error = std::string("cannot list the sessions: ") + error.what();
    }
    ++revision_;
  }
  if (open_task_.ready()) {
    state_.learner_busy = false;
    try {
      adopt(open_task_.take(), false);
    } catch (const std::exception& error) {
      log(LogSource::kSession, std::string("open failed: ") + error.what(), true);
      set_status(std::string("open failed: ") + error.what(), true);
    }
    ++revision_;
  }
}

void ConsoleController::adopt_session(SessionSnapshot snapshot) { adopt(std::move(snapshot), true); }

void ConsoleController::adopt(SessionSnapshot snapshot, bool at_start) {
  const Experiment& e = snapshot.experiment;
  if (!e.trajectory) throw InputError("the session has no trajectory");
  if (std::abs(e.trajectory->sample_time_s - env_.config.timing.sample_s()) > 1e-9) {
    throw InputError(format("the session was recorded with a sample time of %g s, this console runs %g s",
                            e.trajectory->sample_time_s, env_.config.timing.sample_s()));
  }
  // The same sample time from other ticks would save telemetry of another shape than the session's
  // (tick_s x ticks_per_sample rows a trial): every later show, export and resume would refuse it.
  const TimingParameters& recorded = snapshot.config.timing;
  if (!env_.config.timing.same_ticks(recorded)) {
    throw InputError(format(
        "the session was recorded at [timing] tick_s = %g s, ticks_per_sample = %d; this console "
        "runs %g s, %d",
        recorded.tick_s, recorded.ticks_per_sample, env_.config.timing.tick_s, env_.config.timing.ticks_per_sample));
  }
  if (!at_start && (valves_live(state_.engine_state) || state_.run.mode != RunProgress::Mode::kIdle)) {
    throw InputError("disarm before opening a session");
  }
  // The session's gains and weights replace the current ones; the rig's own settings stay.
  Configuration config = state_.config;
  config.controller.k_ff = snapshot.config.controller.k_ff;
  config.controller.k_p = snapshot.config.controller.k_p;
  config.controller.k_i_per_s = snapshot.config.controller.k_i_per_s;
  config.controller.k_d_s = snapshot.config.controller.k_d_s;
  config.ilc = snapshot.config.ilc;
  state_.config = config;
  for (const LogEntry& entry : snapshot.events) state_.log.add(entry);
  state_.experiment = std::move(snapshot.experiment);
  ++experiment_serial_;
  state_.experiment.saved_trials = static_cast<int>(state_.experiment.trials.size());
  state_.experiment.saved_faults = static_cast<int>(state_.experiment.faults.size());
  state_.experiment.settings_changed = false;
  state_.experiment.saved_events = state_.log.total();  // what came with the session is saved
  state_.experiment.next_unsaved = false;
  state_.experiment.release_saved_history();  // on disk: only the newest trials stay in memory
  autosave_failed_ = false;
  arm_where_saved_pending_ = at_start && !state_.experiment.trials.empty();
  state_.inspector = InspectorView{};
  state_.inspector.trial = static_cast<int>(state_.experiment.trials.size()) - 1;
  const Experiment& adopted = state_.experiment;
  log(LogSource::kSession,
      format("opened %s: %s, iterations %s, best RMS %.3f deg", adopted.session_location.c_str(),
             adopted.trajectory->name.c_str(), iteration_range(static_cast<long long>(adopted.trials.size())).c_str(),
             adopted.best_rms_deg()));
  if (!at_start) {
    select_trajectory(adopted.trajectory);
    send_gains();
    rebuild_law();
    state_.screen = Screen::kMain;
    set_status("opened " + adopted.session_location);
  }
}

}  // namespace bellows::ui
