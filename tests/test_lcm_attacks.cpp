// The bus attacks of issue #16 replayed in one process over memq://, message by message with a
// hand-made clock: forged commands on an idle rig (its own limits hold), a forged sequence number
// to take over a session (refused; the engine's own vent still obeyed), forged states (ignored with
// a key, and diagnosed), a lock-out attempt, old-format messages, and the key file's checks.
#include <gtest/gtest.h>

#include <sys/stat.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>

#include "devices/lcm_auth.hpp"
#include "devices/lcm_device.hpp"
#include "devices/lcm_rig_limits.hpp"
#include "engine/base/errors.hpp"
#include "tests/lcm_bench.hpp"
#include "tests/process_runner.hpp"

namespace bellows {
namespace {

using testing::command;
using testing::decode;
using testing::publish;
using testing::pump;
using testing::RigBench;
using testing::SessionBench;
using testing::vented;

LcmKey test_key(std::uint8_t fill) {
  std::array<std::uint8_t, kLcmKeyBytes> bytes{};
  bytes.fill(fill);
  bytes[0] = 1;
  return LcmKey(bytes);
}

constexpr double kPi = std::numbers::pi;

/// Someone on the bus who speaks the protocol but has no key: it takes the rig's offer as soon as
/// it is free and drives inlet A fully open and outlet A shut (B vented), every millisecond.
struct Forger {
  std::int64_t session = 31337;
  std::int64_t seq = 0;
  void act(RigBench& b) {
    const io_state_t s = b.last_state();
    // Bind while the rig serves no one: its offer, or its tripped state (NO_SESSION, naming the session it dropped).
    if (s.session_id == 0 || (s.fault_bits & io_state_t::FAULT_NO_SESSION) != 0) {
      b.send(command(session, ++seq, 0.0, false, s.rig_id, s.binding));
    }
    io_command_t c = command(session, ++seq, 1.0, true, s.rig_id, s.binding);
    c.outlet_duty[0] = 0.0;
    c.inlet_duty[1] = 0.0;
    c.outlet_duty[1] = 1.0;
    b.send(c);
  }
};

struct Extremes {
  double chamber_a_bar = 0.0;
  double angle_deg = 0.0;
};

/// 1.5 s of the forger's commands on an idle rig; the highest chamber A pressure and angle reached.
Extremes forge_for(RigBench& b, double seconds) {
  Forger forger;
  Extremes most;
  b.step(0.0);
  for (double t = 0.0; t < seconds; t += 0.001) {
    forger.act(b);
    b.step(0.001);
    const SimulatedArm::State s = b.arm.state();
    most.chamber_a_bar = std::max(most.chamber_a_bar, s.chamber_Pa[0] / 1e5);
    most.angle_deg = std::max(most.angle_deg, std::abs(s.angle_rad) * 180.0 / kPi);
  }
  return most;
}

TEST(LcmRigLimits, VentTheChamberAboveTheCeilingAndEverythingBeyondTheAngleRange) {
  const RigLimits limits = RigLimits::from(Configuration{});
  EXPECT_DOUBLE_EQ(limits.pressure_ceiling_bar, 1.4 + 0.35);
  ValveCommand open;
  open.joint[0].inlet_duty = {1.0, 0.5};
  open.joint[0].outlet_duty = {0.0, 0.0};
  SensorReading r;
  r.joint[0].chamber_bar = {1.2, 1.2};
  r.joint[0].angle_rad = 0.1;
  LimitedValves out = enforce_rig_limits(open, r, limits);
  EXPECT_EQ(out.fault_bits, 0);
  EXPECT_EQ(out.valves.joint[0].inlet_duty[0], 1.0);
  r.joint[0].chamber_bar = {1.8, 1.2};
  out = enforce_rig_limits(open, r, limits);
  EXPECT_EQ(out.fault_bits, io_state_t::FAULT_PRESSURE_LIMIT);
  EXPECT_EQ(out.valves.joint[0].inlet_duty[0], 0.0);
  EXPECT_EQ(out.valves.joint[0].outlet_duty[0], 1.0);
  EXPECT_EQ(out.valves.joint[0].inlet_duty[1], 0.5) << "only the chamber above the ceiling";
  r.joint[0].chamber_bar = {1.2, std::nan("")};
  EXPECT_EQ(enforce_rig_limits(open, r, limits).valves.joint[0].inlet_duty[1], 0.0)
      << "a NaN pressure counts as too high";
  r.joint[0].chamber_bar = {1.2, 1.2};
  r.joint[0].angle_rad = -1.8;
  out = enforce_rig_limits(open, r, limits);
  EXPECT_TRUE(out.angle_exceeded);
  EXPECT_TRUE(vented(out.valves));
  r.joint[0].angle_rad = std::nan("");
  EXPECT_TRUE(enforce_rig_limits(open, r, limits).angle_exceeded);
}

TEST(LcmRigLimits, ActJointByJoint) {
  const RigLimits limits = RigLimits::from(Configuration{});
  ValveCommand open;
  open.joint_count = 2;
  SensorReading r;
  r.joint_count = 2;
  for (int j = 0; j < 2; ++j) {
    open.joint[static_cast<std::size_t>(j)].inlet_duty = {1.0, 0.5};
    r.joint[static_cast<std::size_t>(j)].chamber_bar = {1.2, 1.2};
  }
  r.joint[1].chamber_bar = {1.2, 1.8};  // the second joint's chamber B above the ceiling
  LimitedValves out = enforce_rig_limits(open, r, limits);
  EXPECT_EQ(out.fault_bits, io_state_t::FAULT_PRESSURE_LIMIT);
  EXPECT_EQ(out.valves.joint[1].inlet_duty[1], 0.0);
  EXPECT_EQ(out.valves.joint[1].outlet_duty[1], 1.0);
  EXPECT_EQ(out.valves.joint[1].inlet_duty[0], 1.0) << "only that chamber";
  EXPECT_EQ(out.valves.joint[0].inlet_duty[1], 0.5) << "the other joint untouched";
  r.joint[1].chamber_bar = {1.2, 1.2};
  EXPECT_EQ(out.angle_joint, -1);
  r.joint[1].angle_rad = -1.8;  // the second joint beyond the range: the whole arm vents
  out = enforce_rig_limits(open, r, limits);
  EXPECT_TRUE(out.angle_exceeded);
  EXPECT_EQ(out.angle_joint, 1) << "the joint beyond the range is named";
  EXPECT_EQ(out.valves.joint_count, 2);
  EXPECT_TRUE(vented(out.valves));
}

TEST(LcmAttacks, ForgedCommandsOnAnIdleRigCannotPassItsPressureCeilingNorItsAngleRange) {
  Configuration unlimited;  // what the rig did before it had limits
  unlimited.lcm.rig_pressure_margin_bar = 5.0;
  unlimited.lcm.rig_angle_limit_deg = 180.0;
  RigBench before(unlimited);
  const Extremes reached = forge_for(before, 1.5);
  std::cerr << "forged commands, no rig limit: chamber A " << reached.chamber_a_bar << " bar, angle "
            << reached.angle_deg << " deg\n";
  ASSERT_GT(reached.chamber_a_bar, 2.5) << "the attack must be able to do harm for this test to mean anything";

  RigBench b;  // the defaults
  const double ceiling = RigLimits::from(b.config).pressure_ceiling_bar;
  const Extremes held = forge_for(b, 1.5);
  std::cerr << "forged commands, rig limits: chamber A " << held.chamber_a_bar << " bar (ceiling " << ceiling
            << "), angle " << held.angle_deg << " deg (range " << b.config.lcm.rig_angle_limit_deg << ")\n";
  // Checked at every 0.1 ms integration step: the chamber rises by far less than 10 mbar in one.
  EXPECT_LE(held.chamber_a_bar, ceiling + 0.01);
  EXPECT_LE(held.angle_deg, b.config.lcm.rig_angle_limit_deg);
  EXPECT_GT(b.rig.stats().pressure_limit_trips, 0u);
  EXPECT_TRUE(b.logged("above the rig's ceiling"));
  EXPECT_NE(b.last_state().fault_bits & io_state_t::FAULT_PRESSURE_LIMIT, 0) << "the state says so";
}

TEST(LcmAttacks, TheRigsAngleRangeVentsDropsTheSessionAndAdmitsNoneUntilTheArmIsBack) {
  Configuration narrow;  // a range the forger reaches under the pressure ceiling
  narrow.trajectory.max_abs_angle_deg = 10.0;
  narrow.safety.angle_limit_deg = 15.0;
  narrow.lcm.rig_angle_limit_deg = 20.0;
  Configuration unlimited = narrow;
  unlimited.lcm.rig_angle_limit_deg = 180.0;
  RigBench before(unlimited);
  const Extremes reached = forge_for(before, 1.5);
  RigBench b(narrow);
  const Extremes held = forge_for(b, 1.5);
  std::cerr << "forged commands: angle " << reached.angle_deg << " deg without the rig's range, " << held.angle_deg
            << " deg with a range of " << narrow.lcm.rig_angle_limit_deg << " deg\n";
  // Vented at the limit, the arm coasts on while its chambers empty; the forger may bind again only
  // once it is back inside.
  EXPECT_LT(held.angle_deg, 0.5 * reached.angle_deg);
  EXPECT_GT(b.rig.stats().angle_limit_trips, 0u);
  EXPECT_TRUE(b.logged("beyond the rig's angle range: vented, session 31337 dropped"));
  EXPECT_TRUE(b.logged("while the arm is beyond the rig's angle range"));
}

TEST(LcmAttacks, AForgedSequenceNumberCannotTakeOverASessionAndTheEnginesVentIsAlwaysObeyed) {
  SessionBench s;
  s.bind();
  s.drive(0.3);
  EXPECT_EQ(s.b.arm.state().command.inlet_duty[0], 0.3);
  const io_state_t served = s.b.last_state();

  // The attack: the session's own id, seq 2^62. Refused as a jump; the engine keeps driving.
  s.b.send(command(4711, std::int64_t{1} << 62, 1.0, true, served.rig_id, served.binding));
  s.drive(0.2);
  EXPECT_EQ(s.b.arm.state().command.inlet_duty[0], 0.2);
  EXPECT_EQ(s.b.rig.stats().commands.out_of_order, 1u);
  EXPECT_TRUE(s.b.logged("jumping from seq"));

  // Without a key a forger can still follow the sequence closely (documented): it gets ahead of
  // the engine, whose next commands are then out of sequence...
  const std::int64_t next = s.b.last_state().command_seq + 1;
  for (int i = 0; i < 5; ++i) s.b.send(command(4711, next + i, 1.0, true, served.rig_id, served.binding));
  s.step();
  EXPECT_EQ(s.b.arm.state().command.inlet_duty[0], 1.0);
  // ...but the engine's vent is obeyed whatever its sequence number,
  s.device.vent();
  s.step();
  s.step(0.001);
  EXPECT_TRUE(vented(s.b.arm.state().command));
  EXPECT_GT(s.b.rig.stats().vents_obeyed_out_of_sequence, 0u);
  // and the engine says what happened instead of calling it a stale sensor.
  s.step();
  EXPECT_GT(s.device.stats().commands_not_ours, 0u);
  EXPECT_NE(s.device.diagnosis().find("another sender is commanding this rig"), std::string::npos)
      << s.device.diagnosis();
}

TEST(LcmAttacks, WithAKeyForgedCommandsAreCountedAndIgnored) {
  SessionBench s(test_key(7));
  s.bind();
  s.drive(0.3);
  const LcmKey key = test_key(7);
  const io_state_t served = s.b.last_state(&key);
  const std::int64_t next = served.command_seq + 1;
  s.b.send(command(4711, std::int64_t{1} << 62, 1.0, true, served.rig_id, served.binding));
  for (int i = 0; i < 5; ++i) s.b.send(command(4711, next + i, 1.0, true, served.rig_id, served.binding));
  s.b.send(command(4711, next, 1.0, true, served.rig_id, served.binding), test_key(8));  // another key
  s.drive(0.2);
  EXPECT_EQ(s.b.arm.state().command.inlet_duty[0], 0.2) << "the engine still drives";
  EXPECT_EQ(s.b.rig.stats().commands.unauthenticated, 7u);
  EXPECT_TRUE(s.b.logged("not signed with this [lcm] key_file"));
  s.step();
  const LcmDeviceStats d = s.device.stats();
  EXPECT_EQ(d.rig_unauthenticated_commands, 7) << "the rig's state says so";
  EXPECT_EQ(d.commands_not_ours, 0u);
  EXPECT_NE(s.device.diagnosis().find("7 unauthenticated"), std::string::npos) << s.device.diagnosis();
  s.device.vent();
  s.step();
  s.step(0.001);
  EXPECT_TRUE(vented(s.b.arm.state().command));
}

TEST(LcmAttacks, WithAKeyForgedStatesAreIgnoredAndDiagnosed) {
  const LcmKey key = test_key(7);
  SessionBench s(key);
  s.bind();
  s.drive(0.0);
  const io_state_t real = s.b.last_state(&key);
  // The attack: readings of 60 deg while the arm is elsewhere.
  io_state_t forged = real;
  forged.seq = real.seq + 1000;
  forged.time_s = real.time_s + 10.0;
  forged.angle_rad = 60.0 * kPi / 180.0;
  publish(s.b.bus, kIoStateChannel, forged);               // unsigned
  publish(s.b.bus, kIoStateChannel, forged, test_key(9));  // signed with another key
  s.step();
  s.step();
  EXPECT_LT(std::abs(s.device.read_sensors().joint[0].angle_rad), 0.1) << "the forged 60 deg never reached the engine";
  const LcmDeviceStats d = s.device.stats();
  EXPECT_EQ(d.states.unauthenticated, 2u);
  EXPECT_GT(d.states.accepted, 0u);
  EXPECT_NE(s.device.diagnosis().find("another sender publishes rig states"), std::string::npos)
      << s.device.diagnosis();
}

TEST(LcmAttacks, WithAKeyNoOneLocksTheOperatorOut) {
  const LcmKey key = test_key(7);
  SessionBench s(key);
  // Before the engine starts, and all along, someone without the key tries to bind and drive.
  for (int i = 0; i < 20; ++i) {
    const io_state_t offer = s.b.states.size() > 0 ? s.b.last_state(&key) : io_state_t{};
    s.b.send(command(999, 1 + 2 * i, 0.0, false, RigBench::kRig, offer.binding));
    s.b.send(command(999, 2 + 2 * i, 1.0, true, RigBench::kRig, offer.binding));
    if (i >= 10) s.device.vent();
    s.step(0.002);
  }
  EXPECT_TRUE(s.device.connected());
  EXPECT_EQ(s.b.rig.stats().serving, 4711);
  EXPECT_EQ(s.b.rig.stats().sessions_served, 1u);
  EXPECT_EQ(s.b.rig.stats().commands.unauthenticated, 40u);
}

TEST(LcmAttacks, OldFormatMessagesAreRefusedWithAClearLine) {
  SessionBench s;
  bellows_v1::io_command_t old_command{};
  old_command.session_id = 5;
  old_command.seq = 1;
  publish(s.b.bus, kIoCommandChannel, old_command);
  bellows_v1::io_state_t old_state{};
  old_state.rig_id = 9;
  old_state.seq = 1;
  publish(s.b.bus, kIoStateChannel, old_state);
  s.device.vent();
  s.step();
  EXPECT_EQ(s.b.rig.stats().commands.old_version, 1u);
  EXPECT_TRUE(s.b.logged("a command of protocol version 1, which this bellows no longer speaks"));
  EXPECT_EQ(s.device.stats().states.old_version, 1u);
  EXPECT_NE(s.device.diagnosis().find("protocol version 1"), std::string::npos);
  std::vector<std::uint8_t> bytes;
  const std::size_t size = encode_into(old_command, bytes);
  io_command_t current{};
  EXPECT_EQ(decode_checked(bytes.data(), size, current), DecodeStatus::kOldVersion);
}

// ---- the key ----

std::filesystem::path key_file(const std::filesystem::path& dir, const std::string& name, std::size_t bytes,
                               mode_t mode) {
  const auto path = testing::write_file(dir, name, std::string(bytes, 'k'));
  chmod(path.c_str(), mode);
  return path;
}

void expect_refused(const std::string& path, const std::string& fragment,
                    const std::filesystem::path& relative_to = {}) {
  try {
    load_lcm_key(path, relative_to);
    ADD_FAILURE() << path << " was accepted";
  } catch (const InputError& error) {
    EXPECT_NE(std::string(error.what()).find(fragment), std::string::npos) << error.what();
    EXPECT_EQ(std::string(error.what()).find('\n'), std::string::npos) << "one line";
  }
}

TEST(LcmKeyFile, OnlyASecretFileOfExactly32BytesIsAKey) {
  const auto dir = testing::make_temp_dir("bellows-lcm-key");
  EXPECT_FALSE(load_lcm_key("").present());
  EXPECT_TRUE(load_lcm_key(key_file(dir, "good.key", 32, 0600).string()).present());
  EXPECT_TRUE(load_lcm_key(key_file(dir, "group.key", 32, 0640).string()).present());
  EXPECT_TRUE(load_lcm_key("good.key", dir).present()) << "relative to the configuration's directory";
  expect_refused(key_file(dir, "world.key", 32, 0644).string(), "readable or writable by everyone");
  expect_refused(key_file(dir, "short.key", 31, 0600).string(), "31 bytes; a key is exactly 32 bytes");
  expect_refused(key_file(dir, "long.key", 33, 0600).string(), "33 bytes");
  expect_refused((dir / "missing.key").string(), "cannot be opened");
  expect_refused(dir.string(), "not a regular file");
  const auto fifo = dir / "fifo.key";
  ASSERT_EQ(mkfifo(fifo.c_str(), 0600), 0);
  expect_refused(fifo.string(), "not a regular file");  // and does not hang
}

TEST(LcmKeyFile, TheMacCoversEveryByteAndOnlyTheKeyMakesIt) {
  const LcmKey key = test_key(3);
  io_command_t c = command(1, 2, 0.5, true, 3, 4);
  std::vector<std::uint8_t> bytes;
  const std::size_t size = encode_signed(c, key, bytes);
  io_command_t out{};
  EXPECT_EQ(decode_checked(bytes.data(), size, out, &key), DecodeStatus::kOk);
  const LcmKey other = test_key(4);
  EXPECT_EQ(decode_checked(bytes.data(), size, out, &other), DecodeStatus::kUnauthenticated);
  for (std::size_t i = 8; i < size; ++i) {  // after the fingerprint: any flipped bit is caught
    bytes[i] ^= 0x10;
    EXPECT_EQ(decode_checked(bytes.data(), size, out, &key), DecodeStatus::kUnauthenticated) << "byte " << i;
    bytes[i] ^= 0x10;
  }
  std::vector<std::uint8_t> unsigned_bytes;
  const std::size_t unsigned_size = encode_signed(c, LcmKey{}, unsigned_bytes);
  EXPECT_EQ(decode_checked(unsigned_bytes.data(), unsigned_size, out, &key), DecodeStatus::kUnauthenticated);
  EXPECT_EQ(decode_checked(unsigned_bytes.data(), unsigned_size, out), DecodeStatus::kOk) << "no key: nothing checked";
}

}  // namespace
}  // namespace bellows
