// libFuzzer target for the rig's command decoder and protocol (devices/lcm_rig_server, what
// `bellows io-sim` runs): the input is a sequence of io_command_t messages (2-byte little-endian
// length, then the bytes) delivered to a RigServer driving the simulated arm, with time passing
// between them. The first byte's bits: 1 the rig has a key (messages of the right size are then
// signed with it when bit 4 is set), 2 messages of the right size are addressed to the rig and its
// current binding (so that the fuzzer reaches the bound states). Whatever arrives: no crash, no
// exception, a rig serving nobody holds its valves vented, and no chamber ever passes the rig's
// pressure ceiling.
#include <cstddef>
#include <cstdint>
#include <vector>

#include "devices/lcm_rig_server.hpp"
#include "engine/config/configuration.hpp"

namespace {

constexpr std::size_t kRigIdOffset = 32;    // after the fingerprint, session_id, seq and utime
constexpr std::size_t kBindingOffset = 40;
constexpr std::int64_t kRigId = 77;

void put_big_endian(std::uint8_t* p, std::int64_t value) {
  for (int i = 7; i >= 0; --i) {
    p[i] = static_cast<std::uint8_t>(value & 0xff);
    value = static_cast<std::int64_t>(static_cast<std::uint64_t>(value) >> 8);
  }
}

bool vented(const bellows::JointValves& c) {  // the simulated arm's one joint
  return c.inlet_duty[0] == 0.0 && c.inlet_duty[1] == 0.0 && c.outlet_duty[0] == 1.0 && c.outlet_duty[1] == 1.0;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size < 1) return 0;
  static const bellows::Configuration config;
  static const std::size_t command_size = bellows::detail::fixed_size<bellows::io_command_t>();
  std::array<std::uint8_t, bellows::kLcmKeyBytes> key_bytes{};
  key_bytes.fill(0x5a);
  const bellows::LcmKey key(key_bytes);
  const std::uint8_t flags = data[0];

  bellows::SimulatedArm arm(config.plant, 1);
  bellows::RigServerParameters params;
  params.period_s = config.timing.tick_s;
  params.command_timeout_s = config.lcm.rig_timeout_s;
  params.seq_window = config.lcm.seq_window;
  params.limits = bellows::RigLimits::from(config);
  if ((flags & 1) != 0) params.key = key;
  const double ceiling_Pa = params.limits.pressure_ceiling_bar * 1e5;
  bellows::RigServer rig(arm, params, kRigId);
  double t = 1.0;
  rig.service(nullptr, t);

  std::vector<std::uint8_t> message;
  for (std::size_t pos = 1; pos + 2 <= size;) {
    std::size_t length = static_cast<std::size_t>(data[pos]) | (static_cast<std::size_t>(data[pos + 1]) << 8);
    pos += 2;
    if (length > size - pos) length = size - pos;
    message.assign(data + pos, data + pos + length);
    pos += length;
    if (message.size() == command_size && (flags & 2) != 0) {
      put_big_endian(message.data() + kRigIdOffset, kRigId);
      put_big_endian(message.data() + kBindingOffset, rig.stats().binding);
    }
    if (message.size() == command_size && (flags & 4) != 0) key.sign(message.data(), message.size());
    rig.on_message("BELLOWS_IO_COMMAND", message.data(), message.size());
    t += 0.0005 * static_cast<double>(1 + (length % 16));  // up to 8 ms: timeouts happen too
    rig.service(nullptr, t);
    const bellows::SimulatedArm::State state = arm.state();
    if (rig.stats().serving == 0 && !vented(state.command)) __builtin_trap();
    // Checked every 0.1 ms integration step; 10 mbar is far more than one step's rise.
    if (state.chamber_Pa[0] > ceiling_Pa + 1e3 || state.chamber_Pa[1] > ceiling_Pa + 1e3) __builtin_trap();
  }
  return 0;
}
