// The checked decoders: every message type round-trips; truncated, foreign, oversized, malformed
// and random bytes are refused with the right reason, never crash, never allocate what a length
// field claims.
#include <gtest/gtest.h>

#include <cctype>
#include <cmath>
#include <fstream>
#include <limits>
#include <random>
#include <sstream>

#include "devices/lcm_auth.hpp"
#include "devices/lcm_codec.hpp"
#include "engine/control/safety.hpp"
#include "tests/test_support.hpp"

namespace bellows {
namespace {

std::vector<std::uint8_t> encode(const auto& message) {
  std::vector<std::uint8_t> bytes;
  bytes.resize(encode_into(message, bytes));
  return bytes;
}

void write_big_endian(std::uint8_t* p, std::uint64_t value, int bytes) {
  for (int i = bytes - 1; i >= 0; --i) {
    p[i] = static_cast<std::uint8_t>(value & 0xff);
    value >>= 8;
  }
}

io_command_t sample_command() {
  io_command_t c{};
  c.session_id = 42;
  c.seq = 7;
  c.utime = 123456;
  c.armed = true;
  c.inlet_duty[0] = 0.25;
  c.inlet_duty[1] = 0.0;
  c.outlet_duty[0] = 0.0;
  c.outlet_duty[1] = 0.75;
  return c;
}

io_state_t sample_state() {
  io_state_t s{};
  s.rig_id = 9;
  s.seq = 3;
  s.session_id = 42;
  s.command_seq = 7;
  s.time_s = 1.5;
  s.angle_rad = 0.3;
  s.chamber_bar[0] = 1.2;
  s.chamber_bar[1] = 1.1;
  s.supply_bar = 3.0;
  s.temperature_K = 293.15;
  return s;
}

trial_summary_t sample_trial(int samples) {
  trial_summary_t t{};
  t.samples = samples;
  t.session_id = 42;
  t.iteration = 3;
  t.rms_deg = 2.5;
  t.correction_bar.resize(static_cast<std::size_t>(samples));
  for (int i = 0; i < samples; ++i) t.correction_bar[static_cast<std::size_t>(i)] = 0.001 * i;
  return t;
}

engine_event_t sample_event(const std::string& text) {
  engine_event_t e{};
  e.session_id = 42;
  e.tick = 1000;
  e.kind = engine_event_t::KIND_FAULT;
  e.text = text;
  return e;
}

TEST(LcmCodec, EveryTypeRoundTrips) {
  {
    io_command_t out{};
    const auto bytes = encode(sample_command());
    ASSERT_EQ(decode_checked(bytes.data(), bytes.size(), out), DecodeStatus::kOk);
    EXPECT_EQ(out.seq, 7);
    EXPECT_EQ(out.outlet_duty[1], 0.75);
    EXPECT_TRUE(out.armed);
  }
  {
    io_state_t out{};
    const auto bytes = encode(sample_state());
    ASSERT_EQ(decode_checked(bytes.data(), bytes.size(), out), DecodeStatus::kOk);
    EXPECT_EQ(out.command_seq, 7);
    EXPECT_EQ(out.chamber_bar[1], 1.1);
  }
  {
    trial_summary_t out{};
    const auto bytes = encode(sample_trial(400));
    ASSERT_EQ(decode_checked(bytes.data(), bytes.size(), out), DecodeStatus::kOk);
    ASSERT_EQ(out.correction_bar.size(), 400u);
    EXPECT_DOUBLE_EQ(out.correction_bar[399], 0.399);
  }
  {
    engine_event_t out{};
    const auto bytes = encode(sample_event("sensor-stale: the sensors stopped updating"));
    ASSERT_EQ(decode_checked(bytes.data(), bytes.size(), out), DecodeStatus::kOk);
    EXPECT_EQ(out.text, "sensor-stale: the sensors stopped updating");
  }
  {
    telemetry_t in{}, out{};
    in.tick = 77;
    in.sample = -1;
    const auto bytes = encode(in);
    ASSERT_EQ(decode_checked(bytes.data(), bytes.size(), out), DecodeStatus::kOk);
    EXPECT_EQ(out.tick, 77);
    EXPECT_EQ(out.sample, -1);
  }
}

TEST(LcmCodec, TruncatedAtEveryLengthIsRefused) {
  const auto check = [](const auto& message, auto out) {
    const auto bytes = encode(message);
    for (std::size_t n = 0; n < bytes.size(); ++n) {
      const DecodeStatus status = decode_checked(bytes.data(), n, out);
      EXPECT_NE(status, DecodeStatus::kOk) << "length " << n << " of " << bytes.size();
      if (n >= 8) {
        EXPECT_TRUE(status == DecodeStatus::kTruncated || status == DecodeStatus::kMalformed) << to_string(status);
      }
    }
  };
  check(sample_command(), io_command_t{});
  check(sample_state(), io_state_t{});
  check(sample_trial(50), trial_summary_t{});
  check(sample_event("fault"), engine_event_t{});
  check(telemetry_t{}, telemetry_t{});
  io_command_t out{};
  EXPECT_EQ(decode_checked(nullptr, 0, out), DecodeStatus::kTruncated);
}

TEST(LcmCodec, AnotherTypesFingerprintIsRefused) {
  io_command_t command{};
  io_state_t state{};
  const auto state_bytes = encode(sample_state());
  EXPECT_EQ(decode_checked(state_bytes.data(), state_bytes.size(), command), DecodeStatus::kWrongType);
  const auto command_bytes = encode(sample_command());
  EXPECT_EQ(decode_checked(command_bytes.data(), command_bytes.size(), state), DecodeStatus::kWrongType);
  auto flipped = command_bytes;
  flipped[3] ^= 0x10;  // a changed type definition has another fingerprint
  EXPECT_EQ(decode_checked(flipped.data(), flipped.size(), command), DecodeStatus::kWrongType);
}

TEST(LcmCodec, AbsurdSizesAreRefusedBeforeAnythingIsAllocated) {
  // A fixed-size message with bytes appended.
  auto command = encode(sample_command());
  command.push_back(0);
  io_command_t c{};
  EXPECT_EQ(decode_checked(command.data(), command.size(), c), DecodeStatus::kTooLarge);

  // A trial summary claiming 2^31-1 samples (16 GiB of doubles), or a negative count.
  auto trial = encode(sample_trial(4));
  trial_summary_t t{};
  write_big_endian(trial.data() + 8, 0x7fffffff, 4);
  EXPECT_EQ(decode_checked(trial.data(), trial.size(), t), DecodeStatus::kTooLarge);
  write_big_endian(trial.data() + 8, 0xffffffff, 4);  // -1
  EXPECT_EQ(decode_checked(trial.data(), trial.size(), t), DecodeStatus::kMalformed);
  write_big_endian(trial.data() + 8, 5, 4);  // one more than the bytes hold
  EXPECT_EQ(decode_checked(trial.data(), trial.size(), t), DecodeStatus::kTruncated);
  write_big_endian(trial.data() + 8, 3, 4);  // one less: bytes left over
  EXPECT_EQ(decode_checked(trial.data(), trial.size(), t), DecodeStatus::kTooLarge);

  // An event whose text length is negative, zero (no terminator) or beyond the message.
  const auto event = encode(sample_event("abc"));
  const std::size_t length_at = event.size() - 4 - 4;  // int32 length, then "abc\0"
  engine_event_t e{};
  for (std::uint32_t length : {0xffffff9cu /* -100 */, 0xffffffffu /* -1 */, 0u, 5u, 0x7fffffffu}) {
    auto bad = event;
    write_big_endian(bad.data() + length_at, length, 4);
    EXPECT_NE(decode_checked(bad.data(), bad.size(), e), DecodeStatus::kOk) << "text length " << length;
  }
  // An event far longer than any the engine sends.
  std::vector<std::uint8_t> huge(kMaxEventBytes + 1, 0);
  std::copy(event.begin(), event.begin() + 8, huge.begin());
  EXPECT_EQ(decode_checked(huge.data(), huge.size(), e), DecodeStatus::kTooLarge);
}

TEST(LcmCodec, RandomBytesNeverDecodeAndNeverCrash) {
  std::mt19937_64 random(7);
  std::uniform_int_distribution<int> byte(0, 255);
  std::uniform_int_distribution<std::size_t> length(0, 600);
  const auto state_fingerprint = encode(sample_state());
  const auto trial_fingerprint = encode(sample_trial(0));
  for (int i = 0; i < 20000; ++i) {
    std::vector<std::uint8_t> bytes(length(random));
    for (auto& b : bytes) b = static_cast<std::uint8_t>(byte(random));
    // Half of them with a right fingerprint, so that the bodies are exercised too.
    const auto& fingerprint = (i % 4 == 1) ? state_fingerprint : trial_fingerprint;
    if (i % 2 == 1 && bytes.size() >= 8) std::copy(fingerprint.begin(), fingerprint.begin() + 8, bytes.begin());
    io_state_t s{};
    trial_summary_t t{};
    engine_event_t e{};
    const DecodeStatus a = decode_checked(bytes.data(), bytes.size(), s);
    const DecodeStatus b = decode_checked(bytes.data(), bytes.size(), t);
    const DecodeStatus c = decode_checked(bytes.data(), bytes.size(), e);
    // A random body of exactly the right size may decode; then it must use every byte.
    if (a == DecodeStatus::kOk) {
      EXPECT_EQ(static_cast<std::size_t>(s.getEncodedSize()), bytes.size());
    }
    if (b == DecodeStatus::kOk) {
      EXPECT_EQ(static_cast<std::size_t>(t.getEncodedSize()), bytes.size());
    }
    EXPECT_NE(c, DecodeStatus::kOk);  // no event fingerprint was written
  }
}

TEST(LcmCodec, CountersSortRefusalsByReason) {
  ReceiveCounters counters;
  counters.count(DecodeStatus::kTruncated);
  counters.count(DecodeStatus::kWrongType);
  counters.count(DecodeStatus::kWrongType);
  counters.count(DecodeStatus::kTooLarge);
  counters.count(DecodeStatus::kMalformed);
  counters.count(DecodeStatus::kOk);  // not accepted until the protocol says so
  counters.invalid();
  counters.foreign();
  counters.out_of_order();
  counters.accepted();
  const ReceiveCounts c = counters.snapshot();
  EXPECT_EQ(c.accepted, 1u);
  EXPECT_EQ(c.wrong_type, 2u);
  EXPECT_EQ(c.ignored(), 8u);
}

TEST(LcmCodec, CommandsARigMayApply) {
  EXPECT_TRUE(valid_command(sample_command()));
  auto c = sample_command();
  c.session_id = 0;
  EXPECT_FALSE(valid_command(c));
  c = sample_command();
  c.seq = 0;
  EXPECT_FALSE(valid_command(c));
  for (double bad : {-0.01, 1.01, std::numeric_limits<double>::quiet_NaN(), std::numeric_limits<double>::infinity()}) {
    c = sample_command();
    c.outlet_duty[1] = bad;
    EXPECT_FALSE(valid_command(c)) << bad;
  }
  // Disarmed: the rig vents whatever the duties say.
  c = sample_command();
  c.armed = false;
  const ValveCommand vented = to_valves(c);
  EXPECT_EQ(vented.joint[0].inlet_duty[0], 0.0);
  EXPECT_EQ(vented.joint[0].outlet_duty[0], 1.0);
  EXPECT_EQ(vented.joint[0].outlet_duty[1], 1.0);
  EXPECT_EQ(to_valves(sample_command()).joint[0].inlet_duty[0], 0.25);
}

TEST(LcmCodec, StatesAnEngineMayRead) {
  EXPECT_TRUE(valid_state(sample_state()));
  auto s = sample_state();
  s.rig_id = 0;
  EXPECT_FALSE(valid_state(s));
  s = sample_state();
  s.time_s = std::numeric_limits<double>::quiet_NaN();
  EXPECT_FALSE(valid_state(s));
  // A NaN sensor value is the engine's guards' business: passed on, not hidden.
  s = sample_state();
  s.angle_rad = std::numeric_limits<double>::quiet_NaN();
  EXPECT_TRUE(valid_state(s));
  EXPECT_TRUE(std::isnan(to_reading(s).joint[0].angle_rad));
}

TEST(LcmCodec, TheIoMessagesCarryOneJointAndRefuseMore) {
  io_command_t command{};
  ValveCommand two_joints;
  two_joints.joint_count = 2;
  two_joints.joint[0].inlet_duty = {0.5, 0.0};
  EXPECT_NE(testing::error_of([&] { fill_command(two_joints, true, command); }).find("carry one joint"),
            std::string::npos);
  EXPECT_EQ(command.inlet_duty[0], 0.0) << "nothing of it filled in";
  fill_command(ValveCommand::vented(), true, command);
  EXPECT_EQ(command.outlet_duty[1], 1.0);
  io_state_t state{};
  SensorReading reading;
  reading.joint_count = 3;
  EXPECT_NE(testing::error_of([&] { fill_state(reading, state); }).find("for 3 joints"), std::string::npos);
  EXPECT_EQ(to_reading(sample_state()).joint_count, 1);
  EXPECT_EQ(to_valves(sample_command()).joint_count, 1);
}

TEST(LcmCodec, TheProtocolDocListsEveryFaultCode) {
  std::ifstream in(std::string(BELLOWS_SOURCE_DIR) + "/docs/lcm-protocol.md");
  ASSERT_TRUE(in) << "docs/lcm-protocol.md missing";
  int listed = 0;
  for (std::string line; std::getline(in, line);) {
    // Rows of the fault table: "| 7 | `sensor-stale` |".
    std::istringstream row(line);
    std::string bar, number, name;
    if (!(row >> bar >> number >> bar >> name) || number.empty() ||
        !std::isdigit(static_cast<unsigned char>(number[0])) || name.size() < 3 || name.front() != '`') {
      continue;
    }
    const int code = std::stoi(number);
    EXPECT_EQ(code, listed) << line;
    EXPECT_EQ(name.substr(1, name.size() - 2), fault_name(static_cast<FaultCode>(code))) << line;
    ++listed;
  }
  // Every code the engine has, and no more: the next one has no name yet.
  EXPECT_GT(listed, 0);
  EXPECT_STREQ(fault_name(static_cast<FaultCode>(listed)), "unknown") << "code " << listed << " is not in the doc";
}

// docs/lcm-protocol.md ("On the wire") shows an example command and state byte for byte, for a lab
// writing a rig from the page alone; tests/check_lcm_protocol_page.py checks them against lcm-gen's
// Python encoder. Here bellows' codec must give the same bytes, and take the page's bytes.
namespace page {

LcmKey example_key() {
  std::array<std::uint8_t, kLcmKeyBytes> bytes{};
  for (std::size_t i = 0; i < bytes.size(); ++i) bytes[i] = static_cast<std::uint8_t>(i);
  return LcmKey(bytes);
}

/// The bytes of the page's dump whose first line is "# NAME, signed with the example key".
std::vector<std::uint8_t> example_bytes(const std::string& name) {
  std::ifstream in(std::string(BELLOWS_SOURCE_DIR) + "/docs/lcm-protocol.md");
  std::string line;
  while (std::getline(in, line) && line != "# " + name + ", signed with the example key") {
  }
  std::vector<std::uint8_t> bytes;
  std::getline(in, line);  // the column heads
  while (std::getline(in, line) && line != "```") {
    std::istringstream columns(line.substr(8, 23));  // "offset  " then up to 8 bytes in hex
    std::string hex;
    while (columns >> hex) bytes.push_back(static_cast<std::uint8_t>(std::stoi(hex, nullptr, 16)));
  }
  return bytes;
}

}  // namespace page

TEST(LcmProtocolPage, TheExampleCommandIsWhatBellowsSends) {
  io_command_t command{};
  command.session_id = 1234567890123;
  command.seq = 1;
  command.utime = 0;
  command.rig_id = 987654321;
  command.binding = 42;
  command.armed = true;
  command.inlet_duty[0] = 0.25;
  command.outlet_duty[1] = 0.5;
  std::vector<std::uint8_t> bytes;
  bytes.resize(encode_signed(command, page::example_key(), bytes));
  const std::vector<std::uint8_t> shown = page::example_bytes("io_command_t");
  ASSERT_EQ(shown.size(), 113u);
  EXPECT_EQ(bytes, shown);
}

TEST(LcmProtocolPage, TheExampleStateIsTakenByBellowsWithTheKeyAndRefusedWithout) {
  std::vector<std::uint8_t> shown = page::example_bytes("io_state_t");
  ASSERT_EQ(shown.size(), 156u);
  const LcmKey key = page::example_key();
  io_state_t state{};
  ASSERT_EQ(decode_checked(shown.data(), shown.size(), state, &key), DecodeStatus::kOk);
  EXPECT_EQ(state.rig_id, 987654321);
  EXPECT_EQ(state.seq, 7);
  EXPECT_EQ(state.session_id, 1234567890123);
  EXPECT_EQ(state.command_seq, 1);
  EXPECT_EQ(state.time_s, 5.0);
  EXPECT_EQ(state.angle_rad, 0.125);
  EXPECT_EQ(state.chamber_bar[1], 1.25);
  EXPECT_EQ(state.temperature_K, 293.15);
  std::vector<std::uint8_t> again;
  again.resize(encode_signed(state, key, again));
  EXPECT_EQ(again, shown);
  shown[64] ^= 1;  // one bit of the angle changed on the way: the MAC no longer fits
  EXPECT_EQ(decode_checked(shown.data(), shown.size(), state, &key), DecodeStatus::kUnauthenticated);
}

}  // namespace
}  // namespace bellows
