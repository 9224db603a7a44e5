// The one protocol of a trial, whoever runs it (a headless run's LearningSession, the console,
// identification): arm the engine if asked to, start the trial through its command queue, follow
// its events until the engine hands the record back. It never blocks: poll() (or observe(), for a
// caller that reads the engine's events itself, as the console does) moves it on and says where the
// trial stands. run_to_completion() is the loop over poll() that lets engine time pass between
// polls, for callers that may wait (headless runs, the simulated clock, identification).
#pragma once

#include <cstdint>
#include <functional>
#include <string>

#include <Eigen/Dense>

#include "engine/base/cancellation.hpp"
#include "engine/base/errors.hpp"
#include "engine/base/parameters.hpp"
#include "engine/rt/engine_driver.hpp"
#include "engine/rt/engine_messages.hpp"
#include "engine/trial/trajectory.hpp"
#include "engine/trial/trial_record.hpp"

namespace bellows {

enum class TrialPhase : std::uint8_t {
  kIdle,      // no trial started yet
  kArming,    // the arm command is sent; the trial is sent once the engine is ARMED
  kWaiting,   // the trial is sent; the engine has not taken it yet
  kSettling,  // the engine took it (RUNNING): holding the trajectory's start
  kRunning,   // tracking the trajectory, at `sample`
  // Finished: the engine holds nothing of the caller's any more.
  kDone,       // the record is complete
  kNotSent,    // the command queue was full: `command` never reached the engine
  kRefused,    // the engine refused `command` (arm or trial): `message` is its reason
  kFaulted,    // the engine faulted (or was disarmed, or aborted it) while it held the trial
  kCancelled,  // cancel(): the engine vented (FAULT); the trial does not count
};
const char* to_string(TrialPhase phase);

struct TrialStatus {
  TrialPhase phase = TrialPhase::kIdle;
  std::uint32_t trial_id = 0;
  int sample = -1;                                 // kRunning: the sample being tracked
  CommandKind command = CommandKind::kStartTrial;  // kNotSent, kRefused: the command concerned
  FaultCode fault = FaultCode::kNone;              // kRefused, kFaulted: the engine's fault then
  std::string message;                             // kNotSent, kRefused, kFaulted: why, one line
  double time_s = 0.0;                             // engine time of the event that moved it last

  bool finished() const { return phase >= TrialPhase::kDone; }
  bool in_progress() const { return phase != TrialPhase::kIdle && !finished(); }
};

/// The engine faulted (or refused) while a trial was run to completion. Carries the fault code.
class EngineFault : public FaultError {  // exit status 3
 public:
  EngineFault(FaultCode code, const std::string& message) : FaultError(message), code_(code) {}
  FaultCode code() const { return code_; }

 private:
  FaultCode code_;
};

class TrialRunner {
 public:
  enum class Arming {
    kIfNeeded,     // arm first unless the engine is ARMED (headless runs, identification)
    kMustBeArmed,  // never arm: an operator arms (the console); the engine refuses a trial unarmed
  };

  /// Whether poll() reads the engine's snapshot. Its latest-value buffer has exactly one reader
  /// thread: a runner beside another reader (a console's, a test's consumer) follows the trial by
  /// the engine's events alone and leaves the snapshot to that reader.
  enum class Snapshot {
    kRead,          // poll() reads it: the trial's progress, and run_to_completion's after_poll sees ticks
    kLeaveToOthers  // poll() reads events only (LearningSession: `bellows run`, or beside a console)
  };

  TrialRunner(EngineCore& core, const TimingParameters& timing, Snapshot snapshot = Snapshot::kRead);

  /// Prepares `record` to the trajectory's samples and joints and starts the trial with
  /// `correction_bar` (N x J). The engine reads and writes all three until the trial is finished():
  /// keep them alive and unchanged until then. Set-up allocates (the record); polling does not.
  /// Throws std::logic_error while another trial is in progress.
  const TrialStatus& start(const Trajectory& trajectory, const Eigen::MatrixXd& correction_bar, TrialRecord& record,
                           Arming arming);

  /// Reads every pending engine event and (Snapshot::kRead) the latest snapshot, and moves the trial
  /// on. For callers that read neither themselves (the engine has one reader of each).
  const TrialStatus& poll();
  /// For a caller that reads the engine's events itself: one of them. True if the trial moved.
  bool observe(const EngineEvent& event);
  /// For a caller that reads the engine's snapshot itself: the latest tick. True if the trial moved.
  bool observe(const TickRecord& tick);

  /// Stops the engine at once (the emergency stop's latch: the next tick vents, whatever is
  /// queued); poll() reports kCancelled once the engine is in FAULT.
  void cancel();
  bool cancelling() const { return cancelling_; }

  /// poll() until the trial is finished, letting engine time pass between polls. A set `stop`
  /// cancels the trial; `after_poll` sees the latest tick after each poll that left the trial in
  /// progress (a caller's guard: it may cancel()).
  const TrialStatus& run_to_completion(EngineDriver& driver, StopFlag stop = nullptr,
                                       const std::function<void(const TickRecord&)>& after_poll = {});

  const TrialStatus& status() const { return status_; }
  /// The latest tick poll() read (default before the first).
  const TickRecord& latest_tick() const { return latest_; }

 private:
  void send_trial();
  void finish(TrialPhase phase, double time_s);
  bool send(const EngineCommand& command);

  EngineCore& core_;
  bool reads_snapshot_ = true;
  int ticks_per_sample_ = 0;
  int settle_ticks_ = 0;
  int settle_max_ticks_ = 0;
  double settle_tolerance_rad_ = 0.0;
  TrialStatus status_;
  TickRecord latest_;
  std::uint32_t next_trial_id_ = 1;
  bool cancelling_ = false;
  // The trial in progress: the caller's, alive until it is finished.
  const Trajectory* trajectory_ = nullptr;
  const Eigen::MatrixXd* correction_ = nullptr;
  TrialRecord* record_ = nullptr;
};

}  // namespace bellows
