// The console's trials and learning: building the law, running a trial through the engine (the
// trial runner, fed by the UI loop's events and snapshot: never waiting), finishing it (summary,
// diagnostics, log), and the run modes (one trial, a step, K iterations).
#include "engine/config/convergence.hpp"
#include "engine/config/joint_convergence.hpp"
#include "engine/base/errors.hpp"
#include "engine/config/joint_learning_factory.hpp"
#include "engine/config/learning_law_factory.hpp"
#include "engine/operator/learning_session.hpp"
#include "ui/canvas.hpp"
#include "ui/console_controller.hpp"
#include "ui/joint_view.hpp"
#include "ui/learning_text.hpp"

namespace bellows::ui {

void ConsoleController::rebuild_law() {
  if (law_build_.busy() || law_update_.busy()) {
    rebuild_pending_ = true;
    return;
  }
  rebuild_pending_ = false;
  state_.law_ready = false;
  law_samples_ = state_.experiment.samples();
  state_.law_name = state_.config.ilc.law;
  law_build_.start(
      [config = state_.config, model = model_, samples = law_samples_, joints = state_.experiment.joints()] {
        BuiltLaw built;
        built.law = make_joint_learning(config, model, joints, samples);
        built.learned_with = learned_with(config);
        // One joint: its law's frequency response; several: the arm's lifted prediction and each joint's.
        const LearningLaw* single = built.law->single_joint_law();
        if (single == nullptr) {
          const JointConvergencePrediction p = predict_joint_convergence(config, joints, samples);
          built.convergence = joint_prediction_summary(p, config.ilc.law);
          built.warning = !p.arm.warning.empty();
          return built;
        }
        const ConvergencePrediction p = predict_convergence(*single, config, samples);
        if (p.available) {
          built.convergence = format(
              "predicted contraction per trial %.3f (nominal model); %.3f at worst for a model "
              "off by up to %.0f %%",
              p.nominal.contraction, p.worst.contraction, 100.0 * p.model_error);
          built.warning = !p.warning.empty();
          if (built.warning) built.convergence = p.warning;
        } else {
          built.convergence = "no convergence prediction for this law";
        }
        return built;
      });
  ++revision_;
}

void ConsoleController::poll_trajectory_load() {
  if (!trajectory_load_.ready()) return;
  std::shared_ptr<const Trajectory> loaded;
  std::string refusal;
  try {
    loaded = trajectory_load_.take();
  } catch (const std::exception& error) {
    refusal = std::string(error.what()) + " (another path, or Esc)";
  }
  ++revision_;
  if (state_.dialog.kind != DialogKind::kTrajectoryPath) return;  // Esc (or a fault) closed the prompt meanwhile
  if (!refusal.empty()) {
    reject_input(std::move(refusal));
    return;
  }
  state_.dialog = {};
  state_.chooser.file_path = trajectory_load_path_;
  state_.chooser.file_trajectory = loaded;
  state_.chooser.preview = loaded;
  state_.chooser.preview_error.clear();
  set_status("preview of " + trajectory_load_path_ + ": Enter uses it");
}

void ConsoleController::poll_tasks() {
  poll_trajectory_load();
  poll_transfer();
  if (law_build_.ready()) {
    try {
      BuiltLaw built = law_build_.take();
      law_ = std::move(built.law);
      law_learned_with_ = std::move(built.learned_with);
      if (law_->samples() != state_.experiment.samples() || law_->joints() != state_.experiment.joints())
        rebuild_pending_ = true;
      state_.law_ready = !rebuild_pending_;
      if (state_.law_ready) {
        if (law_->joints() > 1) state_.law_name = law_->name();  // how the joints are modelled, too
        state_.convergence = built.convergence;
        state_.convergence_warning = built.warning;
        log(LogSource::kLearner,
            format("learning law %s ready (N = %d, M %g, S %g, W %g)", law_->name().c_str(), law_->samples(),
                   state_.config.ilc.m, state_.config.ilc.s, state_.config.ilc.w));
        if (built.warning) log(LogSource::kLearner, built.convergence, true);
      }
    } catch (const std::exception& error) {
      law_.reset();
      state_.law_ready = false;
      log(LogSource::kLearner, std::string("cannot build the learning law: ") + error.what(), true);
      set_status(std::string("cannot build the learning law: ") + error.what(), true);
    }
    ++revision_;
  }
  if (law_update_.ready()) {
    try {
      LawUpdate done = law_update_.take();
      const int from = state_.experiment.trials.back().iteration;
      state_.experiment.trials.back().model_check = done.model_check;
      if (!done.note.empty()) log_event(kModelRefitEvent, LogSource::kLearner, std::move(done.note));
      state_.experiment.set_next(std::move(done.next), "learned from " + std::to_string(from), updating_learned_with_);
      log(LogSource::kLearner, format("new correction learned from iteration %d (max %.4f bar)", from,
                                      state_.experiment.next_correction_bar.cwiseAbs().maxCoeff()));
      state_.run.phase = RunProgress::Phase::kNone;
      if (state_.run.stop_requested || state_.engine_state != EngineState::kArmed) {
        end_run(state_.run.stop_requested ? "stopped by the operator" : "stopped: the valves are not armed", false);
      } else {
        begin_trial_when_saved();  // the learned correction on disk first
      }
    } catch (const std::exception& error) {
      end_run(std::string("learning failed: ") + error.what(), true);
    }
    ++revision_;
  }
  if (rebuild_pending_ && !law_build_.busy() && !law_update_.busy()) rebuild_law();
  poll_session_tasks();
}

void ConsoleController::begin_trial_when_saved() {
  if (autosave_failed_) {  // asking for a trial retries the failed save once
    autosave_failed_ = false;
    log(LogSource::kSession, "retrying the save before the trial");
  }
  if (saves_settled() && !autosave_failed_) {
    begin_trial();
    return;
  }
  begin_after_save_ = true;  // poll_session_tasks() begins it once the save is done
  state_.run.phase = RunProgress::Phase::kNone;
  autosave();
}

void ConsoleController::begin_trial() {
  Experiment& e = state_.experiment;
  if (state_.engine_state != EngineState::kArmed) {
    end_run("arm the valves first (a)", true);
    return;
  }
  if (in_flight_) {  // the engine still holds the last one's buffers
    end_run("a trial is still in progress", true);
    return;
  }
  auto trial = std::make_unique<InFlight>();
  trial->trajectory = e.trajectory;
  trial->correction_bar = e.next_correction_bar;
  trial->origin =
      e.next_tried && !e.trials.empty() ? "same as " + std::to_string(e.trials.back().iteration) : e.next_origin;
  trial->learned_with = e.next_learned_with;
  // The operator arms (a): the runner never does here. It prepares the record and sends the trial.
  note_action_sent();
  const TrialStatus& started =
      runner_.start(*trial->trajectory, trial->correction_bar, trial->record, TrialRunner::Arming::kMustBeArmed);
  if (started.phase == TrialPhase::kNotSent) {
    log(LogSource::kOperator, "command queue full: start trial not sent", true);
    set_status(started.message, true);
    end_run("the trial was not started", true);
    return;
  }
  log(LogSource::kOperator, format("run iteration %d (%s)", e.next_iteration(), trial->origin.c_str()));
  selected_trajectories_.push_back(trial->trajectory);  // the engine holds it until it selects another
  in_flight_ = std::move(trial);
  state_.run.phase = RunProgress::Phase::kSettling;
  state_.run.sample = -1;
  ++revision_;
}

void ConsoleController::on_trial_moved() {
  const TrialStatus& trial = runner_.status();
  switch (trial.phase) {
    case TrialPhase::kSettling:
      state_.run.phase = RunProgress::Phase::kSettling;
      return;
    case TrialPhase::kRunning:
      state_.run.phase = RunProgress::Phase::kRunning;
      state_.run.sample = trial.sample;
      return;
    case TrialPhase::kDone:
      finish_trial(trial.time_s);
      return;
    case TrialPhase::kRefused:  // said by on_event()
      drop_trial("the engine refused the trial");
      return;
    case TrialPhase::kFaulted:
    case TrialPhase::kCancelled:
      log(LogSource::kEngine, format("iteration %d aborted", state_.experiment.next_iteration()), false, trial.time_s);
      drop_trial("trial aborted");
      return;
    case TrialPhase::kIdle:
    case TrialPhase::kArming:
    case TrialPhase::kWaiting:
    case TrialPhase::kNotSent:
      return;
  }
}

void ConsoleController::finish_trial(double time_s) {
  Experiment& e = state_.experiment;
  Trial trial;
  trial.correction_bar = std::move(in_flight_->correction_bar);
  trial.record = std::move(in_flight_->record);
  trial.origin = in_flight_->origin;
  if (env_.capture_trial_end) trial.end_state = env_.capture_trial_end();  // before the engine ticks again
  arm_where_saved_pending_ = false;
  // The RMS over every joint and sample, each joint's, the largest correction of any joint.
  trial.summary = summarize_trial(e.next_iteration(), trial.record, trial.correction_bar,
                                  env_.config.controller.gas.ambient_bar, env_.config.controller.p_max_bar);
  trial.summary.learned_with = std::move(in_flight_->learned_with);
  in_flight_.reset();
  const bool follow = state_.inspector.trial == static_cast<int>(e.trials.size()) - 1;
  e.add_trial(std::move(trial));
  const IterationSummary& s = e.trials.back().summary;
  if (follow || state_.inspector.trial < 0) state_.inspector.trial = static_cast<int>(e.trials.size()) - 1;
  // What learning did: the error's contraction, the change of the correction, and the samples whose
  // set point the clamp cut (where wind-up starts).
  const IterationDiagnostics& d = diagnostics_.observe_latest(e);
  log(LogSource::kEngine,
      format("iteration %d: RMS %.3f deg, max error %.2f deg, max correction %.4f bar%s%s", s.iteration, s.rms_deg,
             s.max_abs_error_deg, s.max_abs_correction_bar,
             d.contraction
                 ? format(", contraction %.3f, correction changed %.4f bar", *d.contraction, d.correction_change_bar)
                       .c_str()
                 : "",
             s.saturated_samples > 0 ? format(", %d samples saturated", s.saturated_samples).c_str() : ""),
      false, time_s);
  if (diagnostics_.windup().joints.empty() && diagnostics_.windup_just_detected()) {
    log(LogSource::kLearner,
        format("wind-up since iteration %d: the correction keeps growing where the set points saturate (%.3f bar "
               "clamped away); the law noilc-constrained avoids it",
               diagnostics_.windup().first_iteration.value_or(s.iteration),
               diagnostics_.windup().max_clamped_excess_bar),
        true, time_s);
  }
  for (const int joint : diagnostics_.windup_just_detected_joints()) {  // several joints: each its own
    log(LogSource::kLearner,
        windup_warning(diagnostics_.windup().joints[static_cast<std::size_t>(joint)], e.joints(), joint), true, time_s);
  }
  if (s.joint_rms_deg.size() > 1) {
    std::string per_joint;
    for (double r : s.joint_rms_deg) {
      if (!per_joint.empty()) per_joint += ' ';
      per_joint += format("%.3f", r);
    }
    log(LogSource::kEngine, format("iteration %d: RMS per joint %s deg", s.iteration, per_joint.c_str()), false,
        time_s);
    set_status(format("iteration %d: RMS %.3f deg (per joint %s)", s.iteration, s.rms_deg, per_joint.c_str()));
  } else {
    set_status(format("iteration %d: RMS %.3f deg", s.iteration, s.rms_deg));
  }
  state_.run.phase = RunProgress::Phase::kNone;
  state_.run.sample = -1;
  // After the rest of the engine's events (the trial's RUNNING -> ARMED is logged after it ended):
  // the log keeps the order things happened in, a batch's "done" last.
  continue_pending_ = true;
}

void ConsoleController::drop_trial(const std::string& why) {
  in_flight_.reset();
  state_.run.phase = RunProgress::Phase::kNone;
  if (state_.run.stop_requested) {
    end_run("trials stopped by the operator; the unfinished trial is not counted", false);
  } else {
    end_run(why + "; it is not counted", state_.engine_state == EngineState::kFault);
  }
}

void ConsoleController::continue_run() {
  RunProgress& r = state_.run;
  if (r.mode != RunProgress::Mode::kBatch) {
    end_run("", false);
    return;
  }
  ++r.batch_done;
  if (r.stop_requested) {
    end_run(format("iterations %s stopped by the operator after iteration %d", batch_span(r).c_str(),
                   state_.experiment.trials.back().iteration),
            false);
  } else if (state_.experiment.rms_rising(state_.stop_after_rises)) {
    end_run(format("iterations %s stopped by itself after iteration %d: the RMS rose %d times in a row",
                   batch_span(r).c_str(), state_.experiment.trials.back().iteration, state_.stop_after_rises),
            true);
  } else if (r.batch_done >= r.batch_total) {
    end_run(format("iterations %s done: RMS %.3f deg", batch_span(r).c_str(),
                   state_.experiment.trials.back().summary.rms_deg),
            false);
  } else {
    step();
  }
}

void ConsoleController::step() {
  Experiment& e = state_.experiment;
  if (!e.next_tried || e.trials.empty()) {
    begin_trial_when_saved();
    return;
  }
  if (!state_.law_ready || !law_ || law_build_.busy()) {
    end_run("the learning law is not ready", true);
    return;
  }
  const Trial& last = e.trials.back();
  state_.run.phase = RunProgress::Phase::kLearning;
  updating_learned_with_ = law_learned_with_;
  const Eigen::Index n = last.correction_bar.rows();
  const double input_limit_bar = env_.config.controller.p_max_bar - env_.config.controller.gas.ambient_bar;
  Eigen::MatrixXd feedback(n, last.correction_bar.cols());
  for (Eigen::Index j = 0; j < feedback.cols(); ++j) {
    feedback.col(j) = last.record.joint_samples(static_cast<int>(j)).u_pid_bar.head(n);
  }
  law_update_.start([law = law_.get(), u = last.correction_bar, error = last.record.normalized_joint_errors(),
                     feedback = std::move(feedback), input_limit_bar] {
    law->set_input_context(feedback, input_limit_bar);  // laws that respect the pressure limits use it
    LawUpdate done{Eigen::MatrixXd(u.rows(), u.cols()), {}, {}};
    law->update(u, error, done.next);
    done.note = law->take_note();
    done.model_check = law->model_check();
    return done;
  });
  ++revision_;
}

void ConsoleController::end_run(const std::string& why, bool important) {
  const bool was_running = state_.run.mode != RunProgress::Mode::kIdle;
  state_.run = RunProgress{};
  if (!why.empty() && was_running) {
    log(LogSource::kOperator, why, important);
    set_status(why, important);
  }
  ++revision_;
}

}  // namespace bellows::ui
