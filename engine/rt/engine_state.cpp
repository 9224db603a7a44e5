#include "engine/rt/engine_state.hpp"

namespace bellows {

Transition transition(EngineState state, CommandKind command) {
  using S = EngineState;
  auto allow = [](S next) { return Transition{true, next, ""}; };
  auto refuse = [state](const char* why) { return Transition{false, state, why}; };
  switch (command) {
    case CommandKind::kEmergencyStop:
      return allow(S::kFault);
    case CommandKind::kHeartbeat:
      return allow(state);
    case CommandKind::kArm:
      if (state == S::kSafe) return allow(S::kArmed);
      if (state == S::kFault) return refuse("a fault is latched: reset it, then arm");
      return refuse("already armed");
    case CommandKind::kDisarm:
      if (state == S::kArmed || state == S::kRunning) return allow(S::kSafe);
      if (state == S::kFault) return refuse("a fault is latched: reset it");
      return refuse("already disarmed");
    case CommandKind::kStartTrial:
      if (state == S::kArmed) return allow(S::kRunning);
      if (state == S::kSafe) return refuse("arm the valves first");
      if (state == S::kRunning) return refuse("a trial is already running");
      return refuse("a fault is latched: reset it and arm");
    case CommandKind::kAbortTrial:
      if (state == S::kRunning) return allow(S::kArmed);
      return refuse("no trial is running");
    case CommandKind::kReset:
      if (state == S::kFault) return allow(S::kSafe);
      return refuse("no fault to reset");
    case CommandKind::kGuard:
      return refuse("a safety guard is not a command");
    case CommandKind::kTrialEnd:
      return refuse("a trial's end is not a command");
    case CommandKind::kSelectTrajectory:
    case CommandKind::kSetGains:
      if (state == S::kSafe || state == S::kArmed) return allow(state);
      if (state == S::kRunning) return refuse("not while a trial is running");
      return refuse("a fault is latched: reset it first");
    case CommandKind::kValvePulse:
      if (state == S::kArmed) return allow(state);
      if (state == S::kSafe) return refuse("arm the valves first");
      if (state == S::kRunning) return refuse("not while a trial is running");
      return refuse("a fault is latched: reset it and arm");
  }
  return refuse("unknown command");
}

const char* to_string(EngineState state) {
  switch (state) {
    case EngineState::kSafe:
      return "SAFE";
    case EngineState::kArmed:
      return "ARMED";
    case EngineState::kRunning:
      return "RUNNING";
    case EngineState::kFault:
      return "FAULT";
  }
  return "?";
}

const char* to_string(CommandKind command) {
  switch (command) {
    case CommandKind::kArm:
      return "arm";
    case CommandKind::kDisarm:
      return "disarm";
    case CommandKind::kStartTrial:
      return "start trial";
    case CommandKind::kAbortTrial:
      return "abort trial";
    case CommandKind::kEmergencyStop:
      return "emergency stop";
    case CommandKind::kReset:
      return "reset";
    case CommandKind::kSelectTrajectory:
      return "select trajectory";
    case CommandKind::kHeartbeat:
      return "heartbeat";
    case CommandKind::kSetGains:
      return "set gains";
    case CommandKind::kValvePulse:
      return "valve pulse";
    case CommandKind::kGuard:
      return "safety guard";
    case CommandKind::kTrialEnd:
      return "trial complete";
  }
  return "?";
}

}  // namespace bellows
