// The console's logic, on the UI thread and without ncurses: it turns the operator's keys into
// engine commands, the engine's events, snapshot and telemetry into the ConsoleState the screens
// show, and runs trials and learning without ever blocking:
//   - trials go through the engine's commands (kStartTrial with a record and a correction this
//     controller owns until the engine hands them back), never through a blocking API;
//   - learning updates, building the law, saving and opening run as background tasks;
//   - it saves as it goes: every completed trial, black box and learned correction is on disk (a
//     background save) before the next trial starts; only the newest trials stay in memory;
//   - an emergency stop is the engine's latch (never queued) and is reported as done only once
//     the engine has acted on it;
//   - it sends the heartbeat every update (at least every 50 ms) unless a drill withholds it.
// The UI thread is the single producer of engine commands and the single consumer of its events,
// its snapshot and one telemetry tap. Tests drive it with a simulated clock.
#pragma once

#include <array>
#include <cstdint>
#include <any>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "engine/model/arm_model.hpp"
#include "engine/rt/engine_core.hpp"
#include "engine/learning/joint_learning.hpp"
#include "engine/rt/realtime_loop.hpp"
#include "engine/operator/trial_runner.hpp"
#include "engine/operator/valve_test.hpp"
#include "ui/background_task.hpp"
#include "ui/console_state.hpp"
#include "ui/console_transfer.hpp"
#include "ui/key_map.hpp"
#include "ui/session_gateway.hpp"
#include "ui/trial_diagnostics.hpp"

namespace bellows::ui {

/// A prompt's verdict on what was typed (ConsoleController::judge_input): refused (`refusal`, the
/// prompt stays open with the typed text and the reason), or taken (the prompt closes, then `then`
/// runs, if any).
struct PromptAnswer {
  std::string refusal;
  std::function<void()> then;
};

/// What the console needs from the program around it.
struct ConsoleEnvironment {
  EngineCore* core = nullptr;
  TelemetryRing* telemetry = nullptr;       // a tap added before the loop started (optional)
  std::function<LatencySummary()> latency;  // the loop's statistics; empty on a simulated clock
  std::string rt_description = "other";
  std::string speed = "1";
  /// The simulated arm on simulated time (console --clock sim): the program around the controller
  /// ticks the engine only while needs_engine_time(), so a study's numbers repeat those of
  /// `bellows run` with the same seed. No heartbeat then (there is no wall time to miss it in).
  bool simulated_clock = false;
  Configuration config;
  /// A library name or a CSV path to a trajectory; throws InputError with the reason.
  std::function<Trajectory(const std::string&)> load_trajectory;
  SessionGateway* sessions = nullptr;
  std::string device_name = "sim";
  std::string device_where;  // the link, e.g. an LCM URL ("in-process" for sim)
  std::string rig_profile;   // the rig profile's name, "" without one
  std::string model_note;    // where config.model came from, when not the configuration (logged at start)
  std::function<bellows::DeviceHealth()> device_health;  // Device::health() (any thread); optional
  std::function<RawInputs()> raw_inputs;                 // Device::raw_inputs() (any thread); optional
  /// Makes `read_rad` (the angle read now) the rig profile's zero: the file and the device; returns
  /// what it did in words, throws InputError. Empty: this device has no profile file to write.
  std::function<std::string(double read_rad)> zero_angle;
  std::uint64_t seed = 1;
  int stop_after_rises = 3;                 // a batch stops when the RMS rose this many times in a row
  std::function<std::string()> clock_text;  // local time "HH:MM:SS"; default: the system clock
  /// Draws the figures of the saved session at `session_location` (SessionGateway::save's answer),
  /// its first `iterations` iterations, from its files (on a background task); returns where.
  /// Empty: not available.
  std::function<std::string(const std::string& session_location, int iterations)> write_figures;
  /// --clock sim: the state the engine and the simulated arm are in at a trial's end (read on the
  /// thread that ticks them, before the next tick), saved with the trial for an exact resume.
  /// Empty: nothing captured (the wall clock).
  std::function<std::any()> capture_trial_end;
  /// A session reopened with --clock sim: arms where its last trial ended (the engine, the arm and
  /// the clock, as `run --resume` puts them) instead of arming afresh; returns "" when it did, else
  /// why not (the console then arms afresh). Offered for the first arm after opening only.
  std::function<std::string()> arm_where_saved;
};

class ConsoleController {
 public:
  ConsoleController(ConsoleEnvironment env, Trajectory trajectory, bool unicode);
  ~ConsoleController();
  ConsoleController(const ConsoleController&) = delete;
  ConsoleController& operator=(const ConsoleController&) = delete;

  /// Starts from a saved session instead of a fresh experiment (call before start()).
  void adopt_session(SessionSnapshot snapshot);
  /// Heartbeat monitoring on, the trajectory selected, the learning law being built.
  void start(double now_s);
  /// One key from the operator (ui/keys.hpp codes).
  void handle_key(int key, double now_s);
  /// Heartbeat, engine events, snapshot, telemetry, background tasks, loop statistics.
  void update(double now_s);
  /// A line the device's I/O thread wrote to stderr (a rig link that stopped answering, and that
  /// it answers again): into the log, as the device's, instead of across the screen.
  void device_said(std::string line);
  void resize(int width, int height);
  /// Latches the engine's emergency stop (vents in its next tick, whatever its queue holds) and
  /// stops any trials. Never waits: the status says "vented" once the engine has acted.
  void emergency_stop(const std::string& why);
  /// Nothing left to save and no save running (autosave caught up, or saving is not available or
  /// failed: then `state().status` says why).
  bool saves_settled() const;
  /// A learning transfer's offer is being computed (in the background) for the chosen trajectory.
  bool transfer_offer_pending() const { return transfer_task_.busy(); }

  const ConsoleState& state() const { return state_; }
  bool quit_requested() const { return quit_requested_; }
  /// Bumped by Ctrl-L: the terminal repaints every cell (clears what another program or a glitch left).
  std::uint64_t repaints() const { return repaints_; }
  /// What is not on disk, naming the trials ("iteration 4 is not saved."); empty when everything
  /// is. The quit confirmation names it; a failed save says it and keeps the data in memory.
  std::string unsaved_work() const { return state_.experiment.unsaved_sentence(); }
  /// Quitting now leaves work the disk did not take although saving is available (a failed save,
  /// or one not finished): the console then says so and exits non-zero (status 4).
  bool quitting_loses_work() const { return state_.sessions_available && !unsaved_work().empty(); }
  /// Bumped by every discrete change (keys, events, results): the screen needs a redraw.
  std::uint64_t revision() const { return revision_; }
  /// Trials or learning in progress: the screen changes continuously.
  bool active() const;
  /// On the simulated clock: whether engine time must pass now: a trial runs, a command that changes
  /// the engine's state (arm, disarm, trial, reset, valve pulse) or an emergency stop waits for its
  /// tick, or the valve test pulses. Settings (trajectory, gains) wait for the next such tick, so
  /// that the ticks, and with them the simulated arm's noise, are those of `bellows run`.
  bool needs_engine_time() const;

 private:
  struct InFlight {  // a trial's buffers, the engine's until the runner says it is finished
    std::shared_ptr<const Trajectory> trajectory;
    Eigen::MatrixXd correction_bar;  // N x J
    TrialRecord record;
    std::string origin;
    LearnedWith learned_with;  // what learned correction_bar (empty: not learned)
  };

  // Engine side (console_controller.cpp).
  [[nodiscard]] bool send(const EngineCommand& command, const char* what);
  [[nodiscard]] bool send_simple(CommandKind kind, const char* what);
  void send_gains();  // the current configuration's PID gains
  void poll_engine(double now_s);
  void on_event(const EngineEvent& event);
  void poll_snapshot_and_telemetry(double now_s);
  void poll_tasks();
  void heartbeat(double now_s);
  void begin_trial();
  void begin_trial_when_saved();  // begin_trial() once everything done so far is on disk
  void on_emergency_stop_delivered();
  /// The trial moved (the runner said so, from an event or the snapshot): show it, or finish it.
  void on_trial_moved();
  void finish_trial(double time_s);
  void drop_trial(const std::string& why);
  void continue_run();
  void step();
  void end_run(const std::string& why, bool important);
  void rebuild_law();
  void select_trajectory(std::shared_ptr<const Trajectory> trajectory);
  void log(LogSource source, std::string text, bool important = false, double engine_time_s = -2.0,
           bool routine = false);
  void set_status(std::string text, bool important = false);
  /// As log(), saved as a session event of `kind` (not a console-log line).
  void log_event(const char* kind, LogSource source, std::string text);

  // Operator side (console_keys.cpp).
  bool handle_dialog_key(int key);
  bool handle_screen_key(int key);
  void perform(Action action);
  /// A dialog the operator was answering, closed by `what` (a fault, the emergency stop): replaced by a
  /// notice that takes the keys typed next until Enter or Esc, so the rest of an answer never runs as commands.
  void interrupt_dialog(const std::string& what);
  void open_dialog(DialogKind kind, std::string title, std::vector<std::string> text, std::string hint,
                   std::string input = {});
  /// Judges the open prompt's text without closing it (handle_dialog_key closes it when taken).
  PromptAnswer judge_input();
  void reject_input(std::string why);  // the prompt stays open with the input and the reason
  /// y/Y closes the dialog and runs `on_yes`; n/N closes it with `status_on_no`; any other key leaves
  /// it open with "... is not an answer here" (then returns false).
  bool answer_yes_no(int key, const std::function<void()>& on_yes, const char* status_on_no);
  /// answer_yes_no for a question whose yes runs `pending` (the action it asks about) once.
  void answer_pending(int key, std::function<void()>& pending, const char* status_on_no);
  void not_an_answer(int key);
  /// The inspector's cursor to the next (+1) or previous (-1) |error| peak of the trial shown.
  void jump_to_error_peak(int step);
  void open_trajectory_chooser();
  void preview_selected_trajectory();
  void use_trajectory(const std::shared_ptr<const Trajectory>& trajectory);
  void poll_trajectory_load();
  /// use_trajectory() once the arm may move: asks to discard unsaved work, then selects it.
  void choose_trajectory(const std::shared_ptr<const Trajectory>& trajectory);
  /// Empty when applied; otherwise why not (nothing changed).
  std::string apply_tuning(int field, const std::string& text);
  /// The next (+1) or previous (-1) learning law; the law is rebuilt and the change logged.
  void choose_law_step(int step);
  void confirm_discard(const std::string& what, std::function<void()> action);
  void quit_when_saved();  // quits once the save in progress is done (it asks again if that save fails)
  void quit_now();

  // The Rig screen and the valve test (console_rig.cpp).
  bool handle_rig_key(int key);
  void start_valve_test();
  void zero_angle();
  void forward_to_valve_test(const EngineEvent& event);
  bool send_valve_test_commands(const std::vector<EngineCommand>& commands);  // false: refused, stopped
  void show_valve_verdicts();
  void refresh_rig(double now_s);
  void add_link_health(DeviceHealth& health);
  // Learning transfer (console_transfer.cpp).
  void remember_taught();  // the current experiment's trials, before another trajectory replaces it
  void offer_transfer();   // a trajectory with no correction: compute what the others taught
  void poll_transfer();
  bool handle_transfer_key(int key);

  // Sessions (console_sessions.cpp).
  void autosave();  // starts a save when something is unsaved and none is running
  void start_save();
  void start_rename(const std::string& name);
  void start_listing();
  void start_open(const std::string& location);
  void start_figures();  // when every trial so far is saved; else after the save that does it
  void launch_figures();
  void poll_session_tasks();
  void adopt(SessionSnapshot snapshot, bool at_start);
  void arm();  // the operator said yes to arming

  ConsoleEnvironment env_;
  DiscreteArmModel model_;
  ConsoleState state_;
  std::uint64_t revision_ = 0;
  bool quit_requested_ = false;
  bool quit_after_save_ = false;
  bool arm_where_saved_pending_ = false;  // the session opened at start may arm where it stopped (arm_where_saved)
  std::uint64_t repaints_ = 0;
  std::uint64_t status_serial_ = 0;  // set_status() calls, to tell a key's own message
  bool continue_pending_ = false;    // a trial finished: the run goes on once this update's events are in
  double newest_event_s_ = -1.0;     // engine time of the newest event polled

  // Trajectories given to the engine, in the order sent, alive until it hands them back (a
  // kTrajectorySelected event for a later one): it may hold a pointer to any of them until then.
  std::vector<std::shared_ptr<const Trajectory>> selected_trajectories_;
  TrialRunner runner_;  // fed the engine's events and snapshot by poll_engine() and the snapshot's reader
  std::unique_ptr<InFlight> in_flight_;

  // The learning (every joint's); never touched while a background update uses it.
  std::unique_ptr<JointLearning> law_;
  LearnedWith law_learned_with_;       // law_'s law and weights
  LearnedWith updating_learned_with_;  // those of the update running (law_update_)
  bool rebuild_pending_ = false;
  int law_samples_ = 0;
  std::function<void()> pending_discard_action_;
  std::function<void()> pending_move_action_;  // kConfirmStartMove: choosing the trajectory, after a yes

  long long action_sent_at_tick_ = -1;  // engine ticks when the last state-changing command was sent
  void note_action_sent() { action_sent_at_tick_ = static_cast<long long>(env_.core->ticks()); }
  double last_heartbeat_s_ = -1.0;
  double drill_started_s_ = 0.0;
  double last_loop_stats_s_ = -1.0;
  double last_fresh_snapshot_s_ = -1.0;
  double now_s_ = 0.0;
  double last_rig_refresh_s_ = -1.0;
  bellows::DeviceHealth link_{};  // the device's link, refreshed with the loop statistics
  std::unique_ptr<ValveTest> valve_test_;
  bool black_box_pending_ = false;
  bool stop_pending_ = false;  // an emergency stop requested, not yet acted on by the engine
  double stop_requested_s_ = 0.0;
  bool begin_after_save_ = false;  // a trial waits for the autosave
  int figures_after_save_ = 0;     // figures of this many trials wait for the autosave (0: none)
  bool autosave_failed_ = false;   // the last save failed: no retry loop, the operator is told
  TrialDiagnostics diagnostics_;
  void export_strip();              // the selected joint's ring into state_.strip
  std::vector<double> strip_time_;  // ring at the ILC rate; angles and set points of every joint
  std::vector<std::array<double, kMaxJoints>> strip_angle_, strip_setpoint_;
  std::size_t strip_next_ = 0, strip_count_ = 0;
  std::uint64_t strip_revision_ = 0, strip_exported_ = 0;

  // Declared last: destroyed (joined) first, before the law and the state they use.
  struct BuiltLaw {
    std::unique_ptr<JointLearning> law;
    std::string convergence;
    bool warning = false;
    LearnedWith learned_with;  // the law and weights it was built with
  };
  BackgroundTask<BuiltLaw> law_build_;
  struct LawUpdate {
    Eigen::MatrixXd next;                   // the correction learned
    std::string note;                       // what the law said (a model refit): a session event
    std::optional<ModelCheck> model_check;  // the trial against its model's prediction
  };
  BackgroundTask<LawUpdate> law_update_;
  BackgroundTask<std::string> save_task_;
  BackgroundTask<std::string> rename_task_;
  BackgroundTask<std::vector<SessionListing>> list_task_;
  BackgroundTask<SessionSnapshot> open_task_;
  BackgroundTask<std::string> figure_task_;
  BackgroundTask<TransferOffer> transfer_task_;
  // A trajectory file read and checked off the UI thread (a large file, a slow mount): the path prompt
  // waits open for it; trajectory_load_path_ is the path it reads.
  BackgroundTask<std::shared_ptr<const Trajectory>> trajectory_load_;
  std::string trajectory_load_path_;
  std::vector<JointTransferSource> taught_;       // earlier experiments of this console
  std::vector<TransferSourceNote> taught_notes_;  // one per taught_ source, for the session's first_correction
  std::vector<std::string> taught_locations_;     // where they are saved (not read back as "saved" sources)
  TransferOffer transfer_offer_;
  bool transfer_wanted_ = false;
  int saving_trials_ = 0;
  int saving_faults_ = 0;
  std::size_t saving_events_ = 0;
  bool saving_settings_changed_ = false;
  std::uint64_t saving_next_revision_ = 0;
  // Bumped whenever state_.experiment is replaced (a trajectory chosen, a session opened): a save
  // that finishes after it belongs to the experiment the operator left, never to the new one.
  std::uint64_t experiment_serial_ = 0;
  std::uint64_t saving_experiment_serial_ = 0;
};

}  // namespace bellows::ui
