// Every (state, command) pair of the safety state machine, allowed and refused.
#include <gtest/gtest.h>

#include "engine/rt/engine_state.hpp"

namespace bellows {
namespace {

using S = EngineState;
using C = CommandKind;

struct Row {
  S from;
  C command;
  bool allowed;
  S next;
};

// The whole table: 4 states x 10 commands.
const Row kTable[] = {
    // SAFE: only arming (and e-stop) changes anything; a trial cannot start.
    {S::kSafe, C::kArm, true, S::kArmed},
    {S::kSafe, C::kDisarm, false, S::kSafe},
    {S::kSafe, C::kStartTrial, false, S::kSafe},
    {S::kSafe, C::kAbortTrial, false, S::kSafe},
    {S::kSafe, C::kEmergencyStop, true, S::kFault},
    {S::kSafe, C::kReset, false, S::kSafe},
    {S::kSafe, C::kSelectTrajectory, true, S::kSafe},
    {S::kSafe, C::kHeartbeat, true, S::kSafe},
    {S::kSafe, C::kSetGains, true, S::kSafe},
    {S::kSafe, C::kValvePulse, false, S::kSafe},
    // ARMED
    {S::kArmed, C::kArm, false, S::kArmed},
    {S::kArmed, C::kDisarm, true, S::kSafe},
    {S::kArmed, C::kStartTrial, true, S::kRunning},
    {S::kArmed, C::kAbortTrial, false, S::kArmed},
    {S::kArmed, C::kEmergencyStop, true, S::kFault},
    {S::kArmed, C::kReset, false, S::kArmed},
    {S::kArmed, C::kSelectTrajectory, true, S::kArmed},
    {S::kArmed, C::kHeartbeat, true, S::kArmed},
    {S::kArmed, C::kSetGains, true, S::kArmed},
    {S::kArmed, C::kValvePulse, true, S::kArmed},
    // RUNNING: nothing changes the trial's conditions under it.
    {S::kRunning, C::kArm, false, S::kRunning},
    {S::kRunning, C::kDisarm, true, S::kSafe},
    {S::kRunning, C::kStartTrial, false, S::kRunning},
    {S::kRunning, C::kAbortTrial, true, S::kArmed},
    {S::kRunning, C::kEmergencyStop, true, S::kFault},
    {S::kRunning, C::kReset, false, S::kRunning},
    {S::kRunning, C::kSelectTrajectory, false, S::kRunning},
    {S::kRunning, C::kHeartbeat, true, S::kRunning},
    {S::kRunning, C::kSetGains, false, S::kRunning},
    {S::kRunning, C::kValvePulse, false, S::kRunning},
    // FAULT: latched. Arming alone cannot clear it; reset leads to SAFE, never straight to ARMED.
    {S::kFault, C::kArm, false, S::kFault},
    {S::kFault, C::kDisarm, false, S::kFault},
    {S::kFault, C::kStartTrial, false, S::kFault},
    {S::kFault, C::kAbortTrial, false, S::kFault},
    {S::kFault, C::kEmergencyStop, true, S::kFault},
    {S::kFault, C::kReset, true, S::kSafe},
    {S::kFault, C::kSelectTrajectory, false, S::kFault},
    {S::kFault, C::kHeartbeat, true, S::kFault},
    {S::kFault, C::kSetGains, false, S::kFault},
    {S::kFault, C::kValvePulse, false, S::kFault},
};

TEST(EngineStateMachine, EveryTransitionAllowedAndRefused) {
  for (const Row& row : kTable) {
    const Transition t = transition(row.from, row.command);
    EXPECT_EQ(t.allowed, row.allowed) << to_string(row.from) << " + " << to_string(row.command);
    EXPECT_EQ(t.next, row.next) << to_string(row.from) << " + " << to_string(row.command);
    if (!t.allowed) {
      EXPECT_GT(std::string(t.refusal).size(), 5u) << "refusals explain themselves";
    }
  }
}

TEST(EngineStateMachine, TableCoversEveryPair) { EXPECT_EQ(std::size(kTable), 4u * 10u); }

TEST(EngineStateMachine, ValvesAreLiveOnlyWhenArmedOrRunning) {
  EXPECT_FALSE(valves_live(S::kSafe));
  EXPECT_TRUE(valves_live(S::kArmed));
  EXPECT_TRUE(valves_live(S::kRunning));
  EXPECT_FALSE(valves_live(S::kFault));
}

}  // namespace
}  // namespace bellows
