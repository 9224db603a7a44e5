// In-process benches for the LCM I/O protocol over memq://, on one thread with a hand-made clock:
// the rig server (io-sim's core) with its simulated arm, and message builders for the tests that
// play the engine, a forger or a broken peer.
#pragma once

#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "devices/lcm_channels.hpp"
#include "devices/lcm_codec.hpp"
#include "devices/lcm_device.hpp"
#include "devices/lcm_rig_server.hpp"
#include "engine/config/configuration.hpp"
#include "tests/lcm_test_support.hpp"
#include "tests/test_support.hpp"

namespace bellows::testing {

/// Dispatches everything queued on a memq bus.
inline void pump(lcm::LCM& bus) {
  while (bus.handleTimeout(0) > 0) {
  }
}

/// Publishes `message`, signed with `key` when it has a MAC field and a key is given.
template <typename Message>
void publish(lcm::LCM& bus, const char* channel, const Message& message, const LcmKey& key = {}) {
  std::vector<std::uint8_t> bytes;
  std::size_t size = 0;
  if constexpr (requires { message.mac; }) size = encode_signed(message, key, bytes);
  else size = encode_into(message, bytes);
  bus.publish(channel, bytes.data(), static_cast<unsigned int>(size));
}

template <typename Message>
Message decode(const Recorded& recorded, const LcmKey* key = nullptr) {
  Message message{};
  EXPECT_EQ(decode_checked(recorded.bytes.data(), recorded.bytes.size(), message, key), DecodeStatus::kOk)
      << recorded.channel;
  return message;
}

inline io_command_t command(std::int64_t session, std::int64_t seq, double inlet_a, bool armed, std::int64_t rig,
                            std::int64_t binding) {
  io_command_t c{};
  c.session_id = session;
  c.seq = seq;
  c.rig_id = rig;
  c.binding = binding;
  c.armed = armed;
  c.inlet_duty[0] = inlet_a;
  c.outlet_duty[1] = 0.2;
  return c;
}

inline void publish_garbage(lcm::LCM& bus, const char* channel) {
  const std::uint8_t short_bytes[5] = {1, 2, 3, 4, 5};
  bus.publish(channel, short_bytes, sizeof short_bytes);  // truncated
  const telemetry_t other{};
  publish(bus, channel, other);  // another type
}

/// A RigServer on memq:// with its simulated arm, its states recorded, its log lines kept.
struct RigBench {
  static constexpr std::int64_t kRig = 77;
  Configuration config;
  SimulatedArm arm;
  lcm::LCM bus{"memq://"};
  std::vector<std::string> log;
  RigServer rig;
  BusRecorder states{kIoStateChannel};
  double t = 100.0;

  explicit RigBench(const Configuration& c = {}, const LcmKey& key = {})
      : config(c), arm(c.plant, 1), rig(arm, parameters(c, key, log), kRig) {
    rig.attach(bus);
    states.attach(bus);
  }
  static RigServerParameters parameters(const Configuration& c, const LcmKey& key, std::vector<std::string>& log) {
    RigServerParameters p;
    p.period_s = c.timing.tick_s;
    p.command_timeout_s = c.lcm.rig_timeout_s;
    p.seq_window = c.lcm.seq_window;
    p.limits = RigLimits::from(c);
    p.key = key;
    p.log = [&log](const std::string& line) { log.push_back(line); };
    return p;
  }
  void step(double dt) {
    pump(bus);
    t += dt;
    rig.service(&bus, t);
    pump(bus);
  }
  io_state_t last_state(const LcmKey* key = nullptr) { return decode<io_state_t>(states.messages().back(), key); }
  void send(const io_command_t& c, const LcmKey& key = {}) { publish(bus, kIoCommandChannel, c, key); }
  bool logged(const std::string& fragment) const {
    for (const std::string& line : log) {
      if (line.find(fragment) != std::string::npos) return true;
    }
    return false;
  }
};

/// The engine's device and the rig on one memq bus, one thread, a hand-made clock. The device's
/// commands go out on `commands_bus` (the rig's bus unless lose_commands(): then on one nobody hears,
/// as when the network drops them).
struct SessionBench {
  RigBench b;
  LcmDevice device;
  BusRecorder commands{kIoCommandChannel};
  lcm::LCM nowhere{"memq://"};
  lcm::LCM* commands_bus = &b.bus;
  explicit SessionBench(const LcmKey& key = {}, const Configuration& c = {}) : b(c, key), device(4711, key) {
    device.attach(b.bus);
    commands.attach(b.bus);
  }
  void lose_commands() { commands_bus = &nowhere; }
  void step(double dt = 0.005) {
    pump(b.bus);
    b.t += dt;
    b.rig.service(&b.bus, b.t);
    device.service(commands_bus, b.t);
    pump(b.bus);
  }
  void bind() {
    for (int i = 0; i < 10 && !device.connected(); ++i) {
      device.vent();
      step();
    }
    ASSERT_TRUE(device.connected());
    ASSERT_EQ(b.rig.stats().serving, 4711);
  }
  void drive(double inlet_a) {
    ValveCommand v;
    v.joint[0].inlet_duty = {inlet_a, 0.0};
    v.joint[0].outlet_duty = {0.0, 1.0};
    device.write_valves(v);
    step();
    step(0.001);  // the rig applies what arrived after its last turn
  }
};

}  // namespace bellows::testing
