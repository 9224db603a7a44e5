// The engine's safety state machine. Pure: a table of which operator command is allowed in which
// state and where it leads, so every transition can be tested without a loop or a device.
//
//   SAFE     disarmed: inlets closed, outlets open (vented)       arm -> ARMED
//   ARMED    valves live, holding the trajectory's start with      start trial -> RUNNING,
//            the PID; a valve pulse (the valve test) hands the     disarm -> SAFE
//            valves to the operator for its ticks, guards running
//   RUNNING  a trial in progress (settle at the start, then the    its end or abort trial -> ARMED,
//            trajectory with the current correction)               disarm -> SAFE (trial handed back)
//   FAULT    latched, vented in the tick the fault was seen        reset -> SAFE only (re-arm explicitly)
// An emergency stop from any state, or a guard while the valves are live, leads to FAULT. Any other
// (state, command) is refused with a reason the operator sees (tests/test_engine_state.cpp checks
// every pair).
#pragma once

#include <cstdint>

namespace bellows {

enum class EngineState : std::uint8_t { kSafe, kArmed, kRunning, kFault };

enum class CommandKind : std::uint8_t {
  kArm,               // SAFE -> ARMED
  kDisarm,            // ARMED/RUNNING -> SAFE (a running trial is abandoned)
  kStartTrial,        // ARMED -> RUNNING
  kAbortTrial,        // RUNNING -> ARMED
  kEmergencyStop,     // any -> FAULT, vents at once
  kReset,             // FAULT -> SAFE
  kSelectTrajectory,  // SAFE/ARMED: the trajectory to hold and run next
  kHeartbeat,         // the console is alive; no transition
  kSetGains,          // SAFE/ARMED: PID gains between trials
  kValvePulse,        // ARMED: the operator sets the valves for a while (the valve test); no transition
  kGuard,             // not a command: the cause of a state change a safety guard made (FAULT)
  kTrialEnd,          // not a command: the cause of RUNNING -> ARMED when a trial ran to its end
};

struct Transition {
  bool allowed = false;
  EngineState next = EngineState::kSafe;
  const char* refusal = "";  // why, when not allowed: for the operator
};

/// What `command` does in `state`.
Transition transition(EngineState state, CommandKind command);

const char* to_string(EngineState state);
const char* to_string(CommandKind command);

/// Whether valves may open in this state (only ARMED and RUNNING).
inline bool valves_live(EngineState state) { return state == EngineState::kArmed || state == EngineState::kRunning; }

}  // namespace bellows
