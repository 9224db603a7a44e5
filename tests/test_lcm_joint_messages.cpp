// The LCM I/O messages of an arm of several joints (issue 14, devices/lcm_io_messages): one joint
// still speaks io_command_t / io_state_t byte for byte; several joints io_joints_command_t /
// io_joints_state_t, checked row by row; a forged joint count or rows that contradict it are
// counted as invalid; a peer of another joint count (a rig speaking today's single-joint messages
// to an arm of two, or the reverse) is counted, refused in one line, and never bound to or obeyed.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>

#include "devices/lcm_channels.hpp"
#include "devices/lcm_device.hpp"
#include "devices/lcm_io_messages.hpp"
#include "devices/lcm_rig_server.hpp"
#include "devices/simulated_arm_chain.hpp"
#include "engine/model/pneumatic_arm_chain_parameters.hpp"
#include "tests/lcm_bench.hpp"

namespace bellows {
namespace {

using testing::decode;
using testing::publish;
using testing::pump;
using testing::RigBench;

std::int64_t fingerprint_of(const testing::Recorded& r) {
  std::int64_t hash = 0;
  for (int i = 0; i < 8; ++i) hash = (hash << 8) | r.bytes[static_cast<std::size_t>(i)];
  return hash;
}

io_joints_command_t joints_command(std::int64_t session, std::int64_t seq, bool armed, std::int64_t rig,
                                   std::int64_t binding, int joints = 2) {
  io_joints_command_t c{};
  c.session_id = session;
  c.seq = seq;
  c.rig_id = rig;
  c.binding = binding;
  c.armed = armed;
  c.joint_count = static_cast<std::int8_t>(joints);
  for (int j = 0; j < joints; ++j) {
    c.inlet_duty[j][0] = 0.6;
    c.outlet_duty[j][1] = 0.4;
  }
  return c;
}

TEST(LcmJointMessages, OneJointIsEncodedAsTodaysMessagesByteForByte) {
  std::array<std::uint8_t, kLcmKeyBytes> key_bytes{};
  key_bytes.fill(7);
  const LcmKey key(key_bytes);
  io_state_t today = {};
  today.rig_id = 5;
  today.seq = 9;
  today.binding = 11;
  today.session_id = 13;
  today.command_seq = 8;
  today.utime = 123456;
  today.time_s = 1.25;
  today.angle_rad = -0.3;
  today.chamber_bar[0] = 1.4;
  today.chamber_bar[1] = 1.1;
  today.supply_bar = 3.0;
  today.temperature_K = 293.0;
  today.fault_bits = 16;
  today.foreign_commands = 2;
  today.unauthenticated_commands = 1;
  for (const LcmKey& k : {LcmKey{}, key}) {
    std::vector<std::uint8_t> expected, got;
    const std::size_t expected_size = encode_signed(today, k, expected);
    const std::size_t size = encode_io_state(widen(today), k, got);
    ASSERT_EQ(size, expected_size);
    EXPECT_EQ(0, std::memcmp(got.data(), expected.data(), size)) << "the state of one joint is today's io_state_t";
  }
  io_command_t command = testing::command(21, 4, 0.35, true, 77, 99);
  command.utime = 42;
  for (const LcmKey& k : {LcmKey{}, key}) {
    std::vector<std::uint8_t> expected, got;
    const std::size_t expected_size = encode_signed(command, k, expected);
    const std::size_t size = encode_io_command(widen(command), k, got);
    ASSERT_EQ(size, expected_size);
    EXPECT_EQ(0, std::memcmp(got.data(), expected.data(), size)) << "the command of one joint is today's io_command_t";
  }
  // And back: either type decodes to the joints form.
  std::vector<std::uint8_t> bytes;
  const std::size_t size = encode_signed(today, key, bytes);
  io_joints_state_t widened{};
  ASSERT_EQ(decode_io_state(bytes.data(), size, widened, &key), DecodeStatus::kOk);
  EXPECT_EQ(widened.joint_count, 1);
  EXPECT_EQ(widened.angle_rad[0], -0.3);
  EXPECT_EQ(widened.chamber_bar[0][1], 1.1);
  EXPECT_TRUE(valid_state(widened));
  EXPECT_EQ(decode_io_state(bytes.data(), size, widened), DecodeStatus::kOk) << "the MAC is checked only with a key";
  bytes[20] ^= 1;
  EXPECT_EQ(decode_io_state(bytes.data(), size, widened, &key), DecodeStatus::kUnauthenticated);
}

TEST(LcmJointMessages, SeveralJointsTravelInTheJointMessagesRoundTrip) {
  SensorReading reading;
  reading.time_s = 2.5;
  reading.joint_count = 3;
  for (int j = 0; j < 3; ++j) {
    reading.joint[static_cast<std::size_t>(j)].angle_rad = 0.1 * (j + 1);
    reading.joint[static_cast<std::size_t>(j)].chamber_bar = {1.2 + j, 1.3 + j};
  }
  reading.supply_bar = 3.0;
  reading.temperature_K = 295.0;
  io_joints_state_t state{};
  state.rig_id = 3;
  state.seq = 1;
  fill_state(reading, state);
  std::vector<std::uint8_t> bytes;
  const std::size_t size = encode_io_state(state, LcmKey{}, bytes);
  EXPECT_EQ(size, detail::fixed_size<io_joints_state_t>());
  io_joints_state_t out{};
  ASSERT_EQ(decode_io_state(bytes.data(), size, out), DecodeStatus::kOk);
  ASSERT_TRUE(valid_state(out));
  const SensorReading back = to_reading(out);
  EXPECT_EQ(back.joint_count, 3);
  for (int j = 0; j < 3; ++j) {
    EXPECT_EQ(back.joint[static_cast<std::size_t>(j)].angle_rad, reading.joint[static_cast<std::size_t>(j)].angle_rad);
    EXPECT_EQ(back.joint[static_cast<std::size_t>(j)].chamber_bar,
              reading.joint[static_cast<std::size_t>(j)].chamber_bar);
  }
  EXPECT_EQ(out.angle_rad[3], 0.0);
  // Signed like the one-joint messages: the MAC covers every byte before it.
  std::array<std::uint8_t, kLcmKeyBytes> key_bytes{};
  key_bytes.fill(3);
  const LcmKey key(key_bytes);
  const std::size_t signed_size = encode_io_state(state, key, bytes);
  ASSERT_EQ(decode_io_state(bytes.data(), signed_size, out, &key), DecodeStatus::kOk);
  bytes[signed_size - kLcmMacBytes - 1] ^= 1;
  EXPECT_EQ(decode_io_state(bytes.data(), signed_size, out, &key), DecodeStatus::kUnauthenticated);

  ValveCommand valves = ValveCommand::vented(2);
  valves.joint[1].inlet_duty = {0.25, 0.0};
  io_joints_command_t command = joints_command(1, 1, true, 2, 3);
  fill_command(valves, true, command);
  EXPECT_EQ(command.joint_count, 2);
  EXPECT_EQ(command.outlet_duty[2][0], 0.0) << "rows beyond the arm are zero";
  ASSERT_TRUE(valid_command(command));
  const ValveCommand applied = to_valves(command);
  EXPECT_EQ(applied.joint_count, 2);
  EXPECT_EQ(applied.joint[1].inlet_duty[0], 0.25);
  EXPECT_EQ(applied.joint[0].outlet_duty[0], 1.0);
  command.armed = false;
  EXPECT_TRUE(testing::vented(to_valves(command)));

  ValveCommand five;
  five.joint_count = 5;
  EXPECT_THROW(fill_command(five, true, command), InputError);
  reading.joint_count = 0;
  EXPECT_THROW(fill_state(reading, state), InputError);
}

TEST(LcmJointMessages, AForgedJointCountOrRowsThatContradictItAreInvalid) {
  const io_joints_command_t good = joints_command(1, 1, true, 2, 3);
  ASSERT_TRUE(valid_command(good));
  for (int joints : {0, -1, 5, 9, 127}) {
    io_joints_command_t c = good;
    c.joint_count = static_cast<std::int8_t>(joints);
    EXPECT_FALSE(valid_command(c)) << joints << " joints";
  }
  io_joints_command_t hidden = good;
  hidden.inlet_duty[2][0] = 0.5;  // a third joint's valves in a two-joint command
  EXPECT_FALSE(valid_command(hidden));
  for (double bad : {std::nan(""), HUGE_VAL, -0.1, 1.5}) {
    io_joints_command_t c = good;
    c.outlet_duty[1][1] = bad;  // the second joint's, like today's single-joint checks
    EXPECT_FALSE(valid_command(c)) << bad;
  }

  io_joints_state_t state{};
  state.rig_id = 1;
  state.seq = 1;
  state.joint_count = 2;
  ASSERT_TRUE(valid_state(state));
  for (int joints : {0, 5, 9}) {
    io_joints_state_t s = state;
    s.joint_count = static_cast<std::int8_t>(joints);
    EXPECT_FALSE(valid_state(s)) << joints << " joints";
  }
  io_joints_state_t extra = state;
  extra.angle_rad[3] = 0.2;
  EXPECT_FALSE(valid_state(extra));
  extra = state;
  extra.chamber_bar[2][1] = NAN;
  EXPECT_FALSE(valid_state(extra));
}

TEST(LcmJointMessages, DecodingRefusesWhatItAlwaysRefused) {
  io_joints_command_t c = joints_command(1, 1, true, 2, 3);
  std::vector<std::uint8_t> bytes;
  const std::size_t size = encode_io_command(c, LcmKey{}, bytes);
  io_joints_command_t out{};
  EXPECT_EQ(decode_io_command(bytes.data(), size - 1, out), DecodeStatus::kTruncated);
  bytes.resize(size + 3);
  EXPECT_EQ(decode_io_command(bytes.data(), size + 3, out), DecodeStatus::kTooLarge);
  EXPECT_EQ(decode_io_command(bytes.data(), 4, out), DecodeStatus::kTruncated);
  std::vector<std::uint8_t> other;
  const std::size_t other_size = encode_into(telemetry_t{}, other);
  EXPECT_EQ(decode_io_command(other.data(), other_size, out), DecodeStatus::kWrongType);
  bellows_v1::io_command_t old{};
  const std::size_t old_size = encode_into(old, other);
  EXPECT_EQ(decode_io_command(other.data(), old_size, out), DecodeStatus::kOldVersion);
  bellows_v1::io_state_t old_state{};
  const std::size_t old_state_size = encode_into(old_state, other);
  io_joints_state_t state{};
  EXPECT_EQ(decode_io_state(other.data(), old_state_size, state), DecodeStatus::kOldVersion);
}

/// RigBench's arm2: the J-joint simulated arm served on memq://.
struct Arm2Rig {
  static constexpr std::int64_t kRig = 88;
  Configuration config;
  SimulatedArmChain arm{pneumatic_chain_of(config.plant, ArmParameters{"arm2"}), 1};
  lcm::LCM bus{"memq://"};
  std::vector<std::string> log;
  RigServer rig{arm, arm.joints(), config.plant.integration_step_s, RigBench::parameters(config, LcmKey{}, log), kRig};
  testing::BusRecorder states{kIoStateChannel};
  double t = 50.0;

  Arm2Rig() {
    rig.attach(bus);
    states.attach(bus);
  }
  void step(double dt = 0.005) {
    pump(bus);
    t += dt;
    rig.service(&bus, t);
    pump(bus);
  }
  io_joints_state_t last_state() {
    io_joints_state_t s{};
    const testing::Recorded r = states.messages().back();
    EXPECT_EQ(decode_io_state(r.bytes.data(), r.bytes.size(), s), DecodeStatus::kOk);
    return s;
  }
  bool logged(const std::string& fragment) const {
    for (const std::string& line : log) {
      if (line.find(fragment) != std::string::npos) return true;
    }
    return false;
  }
};

TEST(LcmJointRig, ServesArm2InTheJointMessagesAndAppliesEachJointsValves) {
  Arm2Rig b;
  b.step(0.0);
  ASSERT_EQ(b.states.size(), 1u);
  EXPECT_EQ(fingerprint_of(b.states.messages().back()), io_joints_state_t::getHash());
  const io_joints_state_t offer = b.last_state();
  EXPECT_EQ(offer.joint_count, 2);
  EXPECT_EQ(offer.fault_bits, io_state_t::FAULT_NO_SESSION);
  publish(b.bus, kIoCommandChannel, joints_command(7, 1, false, Arm2Rig::kRig, offer.binding));  // binds with a vent
  b.step();
  EXPECT_EQ(b.rig.stats().serving, 7);
  io_joints_command_t drive = joints_command(7, 2, true, Arm2Rig::kRig, offer.binding);
  drive.inlet_duty[0][0] = 0.8;  // shoulder: A filled, B vented
  drive.outlet_duty[0][0] = 0.0;
  drive.inlet_duty[0][1] = 0.0;
  drive.outlet_duty[0][1] = 1.0;
  drive.inlet_duty[1][0] = 0.0;  // elbow: A vented, B filled
  drive.outlet_duty[1][0] = 1.0;
  drive.inlet_duty[1][1] = 0.7;
  drive.outlet_duty[1][1] = 0.0;
  publish(b.bus, kIoCommandChannel, drive);
  b.step();
  const auto duties = b.arm.chain().state().duties;
  EXPECT_EQ(duties[0].inlet[0], 0.8);
  EXPECT_EQ(duties[1].inlet[1], 0.7);
  for (int i = 0; i < 40; ++i) {
    publish(b.bus, kIoCommandChannel, [&] {
      drive.seq += 1;
      return drive;
    }());
    b.step();
  }
  const io_joints_state_t s = b.last_state();
  EXPECT_EQ(s.session_id, 7);
  EXPECT_EQ(s.command_seq, drive.seq);
  EXPECT_GT(s.chamber_bar[0][0], s.chamber_bar[0][1] + 0.05) << "the shoulder's A filled";
  EXPECT_GT(s.chamber_bar[1][1], s.chamber_bar[1][0] + 0.05) << "the elbow's B filled";
  EXPECT_EQ(b.rig.stats().commands.ignored(), 0u);
}

TEST(LcmJointRig, ForgedJointCountsAreInvalidAndTodaysSingleJointCommandsAreRefusedInOneLine) {
  Arm2Rig b;
  b.step(0.0);
  const io_joints_state_t offer = b.last_state();
  io_joints_command_t nine = joints_command(7, 1, false, Arm2Rig::kRig, offer.binding);
  nine.joint_count = 9;
  publish(b.bus, kIoCommandChannel, nine);
  io_joints_command_t hidden = joints_command(7, 1, false, Arm2Rig::kRig, offer.binding);
  hidden.inlet_duty[3][0] = 1.0;  // a fourth joint's inlet open in a command for two
  publish(b.bus, kIoCommandChannel, hidden);
  b.step();
  EXPECT_EQ(b.rig.stats().commands.invalid, 2u);
  EXPECT_EQ(b.rig.stats().serving, 0) << "neither bound";

  // An engine of one joint, speaking today's io_command_t, and one of three: neither binds nor drives.
  publish(b.bus, kIoCommandChannel, testing::command(8, 1, 0.0, false, Arm2Rig::kRig, offer.binding));
  publish(b.bus, kIoCommandChannel, testing::command(8, 2, 1.0, true, Arm2Rig::kRig, offer.binding));
  publish(b.bus, kIoCommandChannel, joints_command(9, 1, false, Arm2Rig::kRig, offer.binding, 3));
  b.step();
  const RigServerStats s = b.rig.stats();
  EXPECT_EQ(s.commands.other_joints, 3u);
  EXPECT_EQ(s.serving, 0);
  EXPECT_EQ(s.commands.accepted, 0u);
  EXPECT_EQ(s.vents_obeyed_out_of_sequence, 2u) << "their vents only make the rig safer: obeyed";
  for (const BellowsDuties& joint : {b.arm.chain().state().duties[0], b.arm.chain().state().duties[1]}) {
    EXPECT_EQ(joint.inlet, (std::array<double, 2>{0.0, 0.0})) << "still vented";
    EXPECT_EQ(joint.outlet, (std::array<double, 2>{1.0, 1.0}));
  }
  int lines = 0;
  for (const std::string& line : b.log) lines += line.find("for an arm of") != std::string::npos ? 1 : 0;
  EXPECT_EQ(lines, 1) << "one line, the rest counted";
  EXPECT_TRUE(
      b.logged("a command for an arm of one joint (io_state_t / io_command_t) but this rig's arm has 2 joints"));
  b.step();
  EXPECT_EQ(b.last_state().foreign_commands, 3) << "the states tell the engine what was refused";
}

TEST(LcmJointRig, OneJointThroughTheDeviceConstructorIsTheSingleJointRig) {
  // The same arm, seed and commands through either constructor: the same bytes on the bus.
  const auto run = [](bool as_device) {
    Configuration c;
    SimulatedArm arm(c.plant, 1);
    std::vector<std::string> log;
    lcm::LCM bus("memq://");
    RigServer rig = as_device ? RigServer(static_cast<Device&>(arm), 1, c.plant.integration_step_s,
                                          RigBench::parameters(c, {}, log), 5)
                              : RigServer(arm, RigBench::parameters(c, {}, log), 5);
    testing::BusRecorder states(kIoStateChannel);
    rig.attach(bus);
    states.attach(bus);
    double t = 1.0;
    for (int i = 0; i < 20; ++i) {
      t += 0.005;
      rig.service(&bus, t);
      pump(bus);
    }
    std::vector<std::vector<std::uint8_t>> bytes;
    for (const testing::Recorded& r : states.messages()) bytes.push_back(r.bytes);
    return bytes;
  };
  const auto single = run(false);
  ASSERT_EQ(single.size(), 20u);
  EXPECT_EQ(single.front().size(), detail::fixed_size<io_state_t>());
  // Bindings are random: compare everything but binding (bytes 24..31) and the MAC.
  const auto other = run(true);
  ASSERT_EQ(other.size(), single.size());
  for (std::size_t i = 0; i < single.size(); ++i) {
    ASSERT_EQ(other[i].size(), single[i].size());
    for (std::size_t k = 0; k < single[i].size(); ++k) {
      if (k >= 24 && k < 32) continue;
      EXPECT_EQ(other[i][k], single[i][k]) << "state " << i << " byte " << k;
    }
  }
}

TEST(LcmJointDevice, ArmOfTwoRefusesARigOfTodaysSingleJointMessagesInOneLineAndNeverBinds) {
  lcm::LCM bus{"memq://"};
  LcmDevice device(1234, LcmKey{}, 0.05, 2);
  testing::BusRecorder commands(kIoCommandChannel);
  device.attach(bus);
  commands.attach(bus);
  io_state_t offer{};  // a free rig speaking today's messages
  offer.rig_id = 55;
  offer.seq = 1;
  offer.binding = 66;
  offer.time_s = 0.1;
  offer.fault_bits = io_state_t::FAULT_NO_SESSION;
  double t = 1.0;
  for (int i = 0; i < 5; ++i) {
    publish(bus, kIoStateChannel, offer);
    offer.seq += 1;
    offer.time_s += 0.005;
    device.vent();
    pump(bus);
    t += 0.005;
    device.service(&bus, t);
    pump(bus);
  }
  // Forged joint states: a count of 9, and a third joint hidden in a state of two.
  io_joints_state_t forged{};
  forged.rig_id = 55;
  forged.seq = 100;
  forged.binding = 66;
  forged.time_s = 1.0;
  forged.joint_count = 9;
  publish(bus, kIoStateChannel, forged);
  forged.joint_count = 2;
  forged.angle_rad[2] = 0.5;
  publish(bus, kIoStateChannel, forged);
  pump(bus);
  const LcmDeviceStats s = device.stats();
  EXPECT_EQ(s.states.invalid, 2u);
  EXPECT_EQ(s.states.other_joints, 5u);
  EXPECT_EQ(s.states.accepted, 0u);
  EXPECT_EQ(s.rig_id, 0) << "never bound";
  EXPECT_FALSE(device.connected());
  ASSERT_GT(commands.size(), 0u);
  const testing::Recorded last = commands.messages().back();
  EXPECT_EQ(fingerprint_of(last), io_joints_command_t::getHash()) << "an arm of two speaks the joint messages";
  io_joints_command_t c{};
  ASSERT_EQ(decode_io_command(last.bytes.data(), last.bytes.size(), c), DecodeStatus::kOk);
  EXPECT_EQ(c.joint_count, 2);
  EXPECT_EQ(c.rig_id, 0) << "addressed to no rig";
  EXPECT_EQ(device.diagnosis(),
            "a rig on this bus serves an arm of one joint (io_state_t / io_command_t) but this arm has 2 joints: 5 "
            "states ignored "
            "(the engine's [arm] must be the rig's: docs/lcm-protocol.md)");
}

TEST(LcmJointDevice, ArmOfOneRefusesARigOfTwoAndSendsTodaysMessages) {
  Arm2Rig rig;
  LcmDevice device(1234);  // one joint, as always
  testing::BusRecorder commands(kIoCommandChannel);
  device.attach(rig.bus);
  commands.attach(rig.bus);
  for (int i = 0; i < 6; ++i) {
    device.vent();
    device.service(&rig.bus, rig.t);
    rig.step();
  }
  EXPECT_EQ(device.stats().states.other_joints, device.stats().states.ignored());
  EXPECT_GE(device.stats().states.other_joints, 5u);
  EXPECT_EQ(device.stats().rig_id, 0);
  EXPECT_EQ(rig.rig.stats().serving, 0);
  EXPECT_NE(device.diagnosis().find("serves an arm of 2 joints but this arm has one joint"), std::string::npos)
      << device.diagnosis();
  const testing::Recorded last = commands.messages().back();
  EXPECT_EQ(fingerprint_of(last), io_command_t::getHash());
  EXPECT_EQ(last.bytes.size(), detail::fixed_size<io_command_t>());
  EXPECT_EQ(decode<io_command_t>(last).rig_id, 0);
}

TEST(LcmJointDevice, ArmOfTwoWritesBothJointsAndReadsBoth) {
  Arm2Rig rig;
  LcmDevice device(1234, LcmKey{}, 0.05, 2);
  device.attach(rig.bus);
  for (int i = 0; i < 4 && !device.connected(); ++i) {
    device.vent();
    device.service(&rig.bus, rig.t);
    rig.step();
    device.service(&rig.bus, rig.t);
  }
  ASSERT_TRUE(device.connected());
  EXPECT_EQ(rig.rig.stats().serving, 1234);
  ValveCommand valves = ValveCommand::vented(2);
  valves.joint[0].inlet_duty = {0.9, NAN};  // NaN inlet: closed
  valves.joint[1].inlet_duty = {0.0, 1.7};  // clamped
  valves.joint[1].outlet_duty = {1.0, 0.0};
  device.write_valves(valves);
  device.service(&rig.bus, rig.t);
  rig.step();
  device.service(&rig.bus, rig.t);
  const auto duties = rig.arm.chain().state().duties;
  EXPECT_EQ(duties[0].inlet, (std::array<double, 2>{0.9, 0.0}));
  EXPECT_EQ(duties[1].inlet, (std::array<double, 2>{0.0, 1.0}));
  const SensorReading reading = device.read_sensors();
  EXPECT_EQ(reading.joint_count, 2);
  EXPECT_GT(reading.supply_bar, 2.5);
  ValveCommand three = ValveCommand::vented(3);
  three.joint[0].inlet_duty = {1.0, 1.0};
  device.write_valves(three);  // meant for another arm: every joint vented
  device.service(&rig.bus, rig.t);
  rig.step();
  EXPECT_EQ(rig.arm.chain().state().duties[0].inlet, (std::array<double, 2>{0.0, 0.0}));
  EXPECT_EQ(rig.arm.chain().state().duties[1].outlet, (std::array<double, 2>{1.0, 1.0}));
  EXPECT_THROW(LcmDevice(1, LcmKey{}, 0.05, 5), InputError);
}

}  // namespace
}  // namespace bellows
