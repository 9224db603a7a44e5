// A rig that vented on its command timeout is named for why its commands stopped: this host sent
// none for the rig's whole timeout (its engine or I/O thread did not run), or it sent them and the
// network lost them; and the longest this host went between two commands is in the device's stats
// (`run --json`'s lcm.rig.longest_command_gap_ms). Over memq://, one thread, a hand-made clock
// (tests/lcm_bench.hpp).
#include <gtest/gtest.h>

#include <string>

#include "devices/lcm_device.hpp"
#include "engine/control/fault_code.hpp"
#include "tests/lcm_bench.hpp"

namespace bellows {
namespace {

using testing::SessionBench;

/// Steps the bench until the device reports a fault (at most `seconds`), writing `inlet_a` to the
/// valves each step when `keep_commanding`.
DeviceFault run_until_fault(SessionBench& s, double seconds, bool keep_commanding) {
  DeviceFault fault;
  ValveCommand v;
  v.joint[0].inlet_duty = {0.3, 0.0};
  v.joint[0].outlet_duty = {0.0, 1.0};
  for (double waited_s = 0.0; waited_s < seconds; waited_s += 0.005) {
    if (keep_commanding) s.device.write_valves(v);
    s.step();
    if (s.device.take_fault(fault)) break;
  }
  return fault;
}

TEST(LcmRigTimeoutNamed, AHostThatSentNothingForTheRigsTimeoutIsNamedNotTheNetwork) {
  SessionBench s;
  s.bind();
  s.drive(0.3);
  const double timeout_s = s.b.config.lcm.rig_timeout_s;
  // The engine writes nothing more: no command leaves this host, as when its threads are held off the cores.
  const DeviceFault fault = run_until_fault(s, 10 * timeout_s, false);
  ASSERT_EQ(fault.code, FaultCode::kRigTimeout) << fault.text.data();
  const std::string message = fault.text.data();
  EXPECT_NE(message.find("vented: this host sent it no command for"), std::string::npos) << message;
  EXPECT_NE(message.find("longer than its 50 ms timeout"), std::string::npos) << message;
  EXPECT_EQ(message.find("network"), std::string::npos) << message;
  EXPECT_NE(s.b.last_state().fault_bits & io_state_t::FAULT_COMMAND_TIMEOUT, 0) << "the rig did time out";
}

TEST(LcmRigTimeoutNamed, CommandsSentButLostOnTheWayAreNamedTheNetwork) {
  SessionBench s;
  s.bind();
  s.drive(0.3);
  const double timeout_s = s.b.config.lcm.rig_timeout_s;
  // The engine goes on commanding every 5 ms, but nothing it publishes reaches the rig. The longest
  // wait is 6 ms: drive()'s last millisecond (the rig's turn to apply) and then 5 ms to the next.
  s.lose_commands();
  const DeviceFault fault = run_until_fault(s, 10 * timeout_s, true);
  ASSERT_EQ(fault.code, FaultCode::kRigTimeout) << fault.text.data();
  const std::string message = fault.text.data();
  EXPECT_NE(message.find("though this host sent one at least every 6 ms: check the network"), std::string::npos)
      << message;
  EXPECT_EQ(message.find("this host sent it no command"), std::string::npos) << message;
}

TEST(LcmRigTimeoutNamed, TheRigsAnnouncedTimeoutIsTheOneJudgedAgainst) {
  // The device was told 50 ms ([lcm] rig_timeout_s); the rig announces 400 ms and times out at that.
  Configuration slow;
  slow.lcm.rig_timeout_s = 0.4;
  SessionBench s(LcmKey{}, slow);
  s.bind();
  RigAnnouncedLimits announced;
  // Inlets closed (armed all the same), so that the rig's pressure ceiling stays out of it.
  for (int i = 0; i < 400 && !s.device.read_announced_limits(announced); ++i) s.drive(0.0);
  ASSERT_DOUBLE_EQ(announced.command_timeout_s, 0.4) << "the rig announced no limits";
  const DeviceFault fault = run_until_fault(s, 2.0, false);
  ASSERT_EQ(fault.code, FaultCode::kRigTimeout) << fault.text.data();
  const std::string message = fault.text.data();
  EXPECT_NE(message.find("longer than its 400 ms timeout"), std::string::npos) << message;
}

TEST(LcmCommandGap, TheLongestWaitBetweenTwoOfTheEnginesCommandsIsCountedButNotAHold) {
  SessionBench s;
  s.bind();
  for (int i = 0; i < 10; ++i) s.drive(0.0);  // a command every 6 ms (drive(): 5 ms, then 1 ms)
  EXPECT_NEAR(s.device.stats().longest_command_gap_s, 0.006, 1e-9);
  for (int i = 0; i < 5; ++i) s.step();  // 25 ms without a command: the engine late, under the rig's 50 ms
  s.drive(0.0);
  EXPECT_NEAR(s.device.stats().longest_command_gap_s, 0.031, 1e-9) << "the 1 ms, the 25 ms, then 5 ms to the next";
  // The rig check holds the commands back on purpose: not a gap of the engine's.
  s.device.hold_commands(true);
  for (int i = 0; i < 20; ++i) s.drive(0.0);
  s.device.hold_commands(false);
  for (int i = 0; i < 10; ++i) s.drive(0.0);
  EXPECT_NEAR(s.device.stats().longest_command_gap_s, 0.031, 1e-9);
}

}  // namespace
}  // namespace bellows
