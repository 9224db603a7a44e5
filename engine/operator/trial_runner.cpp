#include "engine/operator/trial_runner.hpp"

#include <cmath>
#include <stdexcept>

#include "engine/base/units.hpp"

namespace bellows {

const char* to_string(TrialPhase phase) {
  switch (phase) {
    case TrialPhase::kIdle:
      return "idle";
    case TrialPhase::kArming:
      return "arming";
    case TrialPhase::kWaiting:
      return "waiting";
    case TrialPhase::kSettling:
      return "settling";
    case TrialPhase::kRunning:
      return "running";
    case TrialPhase::kDone:
      return "done";
    case TrialPhase::kNotSent:
      return "not sent";
    case TrialPhase::kRefused:
      return "refused";
    case TrialPhase::kFaulted:
      return "faulted";
    case TrialPhase::kCancelled:
      return "cancelled";
  }
  return "?";
}

TrialRunner::TrialRunner(EngineCore& core, const TimingParameters& timing, Snapshot snapshot)
    : core_(core),
      reads_snapshot_(snapshot == Snapshot::kRead),
      ticks_per_sample_(timing.ticks_per_sample),
      settle_ticks_(static_cast<int>(std::lround(timing.settle_s / timing.tick_s))),
      settle_max_ticks_(static_cast<int>(std::lround(timing.settle_max_s / timing.tick_s))),
      settle_tolerance_rad_(timing.settle_tolerance_deg * kRadPerDeg) {}

const TrialStatus& TrialRunner::start(const Trajectory& trajectory, const Eigen::MatrixXd& correction_bar,
                                      TrialRecord& record, Arming arming) {
  if (status_.in_progress()) throw std::logic_error("TrialRunner::start: a trial is in progress");
  trajectory_ = &trajectory;
  correction_ = &correction_bar;
  record_ = &record;
  record.prepare(trajectory.learning_samples(), ticks_per_sample_, trajectory.joints());
  cancelling_ = false;
  status_ = TrialStatus{};
  status_.trial_id = next_trial_id_++;
  if (arming == Arming::kIfNeeded && core_.state() != EngineState::kArmed) {
    status_.phase = TrialPhase::kArming;
    status_.command = CommandKind::kArm;
    if (!send(EngineCommand::of(CommandKind::kArm))) finish(TrialPhase::kNotSent, status_.time_s);
    return status_;
  }
  send_trial();
  return status_;
}

void TrialRunner::send_trial() {
  status_.phase = TrialPhase::kWaiting;
  status_.command = CommandKind::kStartTrial;
  EngineCommand command =
      EngineCommand::start_trial(*trajectory_, *correction_, *record_, settle_ticks_, status_.trial_id);
  command.settle_max_ticks = settle_max_ticks_;
  command.settle_tolerance_rad = settle_tolerance_rad_;
  if (!send(command)) {
    finish(TrialPhase::kNotSent, status_.time_s);
  }
}

bool TrialRunner::send(const EngineCommand& command) {
  if (core_.send(command)) return true;
  status_.message = std::string("the engine's command queue is full: ") + to_string(command.kind) + " not sent";
  return false;
}

void TrialRunner::finish(TrialPhase phase, double time_s) {
  status_.phase = phase;
  status_.time_s = time_s;
  status_.sample = -1;
  trajectory_ = nullptr;  // the engine handed everything back (or never had it)
  correction_ = nullptr;
  record_ = nullptr;
}

bool TrialRunner::observe(const EngineEvent& event) {
  // Cancelling, only the engine's FAULT ends the trial (poll() looks): whatever it reports before
  // the stop lands, the trial does not count.
  if (!status_.in_progress() || cancelling_) return false;
  const TrialPhase phase = status_.phase;
  const bool held = phase == TrialPhase::kWaiting || phase == TrialPhase::kSettling || phase == TrialPhase::kRunning;
  switch (event.kind) {
    case EventKind::kStateChanged:
      if (phase == TrialPhase::kArming && event.to == EngineState::kArmed) {
        status_.time_s = event.time_s;
        send_trial();
        return true;
      }
      if (phase == TrialPhase::kWaiting && event.to == EngineState::kRunning) {
        status_.phase = TrialPhase::kSettling;
        status_.time_s = event.time_s;
        return true;
      }
      return false;
    case EventKind::kCommandRefused:
      if ((phase == TrialPhase::kArming && event.command == CommandKind::kArm) ||
          (phase == TrialPhase::kWaiting && event.command == CommandKind::kStartTrial)) {
        status_.command = event.command;
        status_.fault = core_.fault();
        status_.message = event.refusal;
        finish(TrialPhase::kRefused, event.time_s);
        return true;
      }
      return false;
    case EventKind::kTrialComplete:
      if (!held || event.trial_id != status_.trial_id) return false;
      finish(TrialPhase::kDone, event.time_s);
      return true;
    case EventKind::kTrialAborted:
      if (!held || event.trial_id != status_.trial_id) return false;
      status_.fault = core_.fault();
      status_.message =
          event.detail[0] != '\0' ? std::string(event.detail.data()) : std::string(fault_message(status_.fault));
      finish(TrialPhase::kFaulted, event.time_s);
      return true;
    case EventKind::kFault:  // a held trial ends with its kTrialAborted; an arm is refused or not
    case EventKind::kValvePulseDone:
    case EventKind::kWarning:
    case EventKind::kTrajectorySelected:
      return false;
  }
  return false;
}

bool TrialRunner::observe(const TickRecord& tick) {
  const TrialPhase phase = status_.phase;
  if ((phase != TrialPhase::kSettling && phase != TrialPhase::kRunning) || cancelling_) return false;
  if (tick.trial_id != status_.trial_id || tick.sample < 0 || tick.sample == status_.sample) return false;
  status_.phase = TrialPhase::kRunning;
  status_.sample = tick.sample;
  return true;
}

const TrialStatus& TrialRunner::poll() {
  EngineEvent event;
  while (core_.poll_event(event)) observe(event);
  if (reads_snapshot_ && core_.read_snapshot(latest_)) observe(latest_);
  if (cancelling_ && status_.in_progress() && core_.state() == EngineState::kFault) {
    status_.fault = core_.fault();
    status_.message = "stopped: valves vented";
    finish(TrialPhase::kCancelled, reads_snapshot_ ? latest_.time_s : status_.time_s);
  }
  return status_;
}

void TrialRunner::cancel() {
  if (!status_.in_progress()) return;
  core_.request_emergency_stop();  // a latch: the next tick vents, whatever is queued
  cancelling_ = true;
}

const TrialStatus& TrialRunner::run_to_completion(EngineDriver& driver, StopFlag stop,
                                                  const std::function<void(const TickRecord&)>& after_poll) {
  for (;;) {
    poll();
    if (!status_.in_progress()) return status_;
    if (!cancelling_ && stop_is_requested(stop)) cancel();
    if (!cancelling_ && after_poll) after_poll(latest_);
    driver.await();
  }
}

}  // namespace bellows
