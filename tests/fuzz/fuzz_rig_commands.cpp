// libFuzzer target for the rig's command decoder and protocol (devices/lcm_rig_server, what
// `bellows io-sim` runs): the input is a sequence of command messages (2-byte little-endian length,
// then the bytes) delivered to a RigServer driving a simulated arm, with time passing between them.
// The first byte's bits: 1 the rig has a key (messages of a command's size are then signed with it
// when bit 4 is set), 2 messages of a command's size are addressed to the rig and its current
// binding (so that the fuzzer reaches the bound states), 8 the arm is the two-joint chain (arm2,
// whose rig speaks io_joints_command_t and must refuse io_command_t) instead of the one-joint arm
// (which must refuse io_joints_command_t). Both commands' sizes are addressed and signed, so that
// well-formed messages of the other kind reach the rig too. Whatever arrives: no crash, no
// exception, a rig serving nobody holds every joint's valves vented, and no chamber of any joint ever
// passes the rig's pressure ceiling.
#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "devices/lcm_rig_server.hpp"
#include "devices/simulated_arm_chain.hpp"
#include "engine/config/configuration.hpp"
#include "engine/model/pneumatic_arm_chain_parameters.hpp"

namespace {

constexpr std::size_t kRigIdOffset = 32;  // after the fingerprint, session_id, seq and utime
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

bool vented(const bellows::BellowsDuties& d) {  // one joint of the chain
  return d.inlet[0] == 0.0 && d.inlet[1] == 0.0 && d.outlet[0] == 1.0 && d.outlet[1] == 1.0;
}

/// What the rig's arm shows after each message: every joint vented, the highest chamber pressure.
struct ArmView {
  bool all_vented = true;
  double highest_chamber_Pa = 0.0;
};

ArmView view_of(const bellows::SimulatedArm& arm) {
  const bellows::SimulatedArm::State state = arm.state();
  return {vented(state.command), std::max(state.chamber_Pa[0], state.chamber_Pa[1])};
}

ArmView view_of(const bellows::SimulatedArmChain& arm) {
  const bellows::PneumaticArmChain::State state = arm.chain().state();
  ArmView view;
  for (int j = 0; j < arm.joints(); ++j) {
    view.all_vented = view.all_vented && vented(state.duties[static_cast<std::size_t>(j)]);
    for (double chamber_Pa : state.chamber_Pa[static_cast<std::size_t>(j)]) {
      view.highest_chamber_Pa = std::max(view.highest_chamber_Pa, chamber_Pa);
    }
  }
  return view;
}

/// Delivers the input's messages to a rig serving `arm` and checks the invariants after each.
template <typename Arm>
void serve(Arm& arm, bellows::RigServer& rig, double ceiling_Pa, const bellows::LcmKey& key, std::uint8_t flags,
           const std::uint8_t* data, std::size_t size) {
  static const std::size_t command_sizes[] = {bellows::detail::fixed_size<bellows::io_command_t>(),
                                              bellows::detail::fixed_size<bellows::io_joints_command_t>()};
  const auto is_command_size = [](std::size_t n) { return n == command_sizes[0] || n == command_sizes[1]; };
  double t = 1.0;
  rig.service(nullptr, t);
  std::vector<std::uint8_t> message;
  for (std::size_t pos = 1; pos + 2 <= size;) {
    std::size_t length = static_cast<std::size_t>(data[pos]) | (static_cast<std::size_t>(data[pos + 1]) << 8);
    pos += 2;
    if (length > size - pos) length = size - pos;
    message.assign(data + pos, data + pos + length);
    pos += length;
    if (is_command_size(message.size()) && (flags & 2) != 0) {  // both messages: rig_id, binding at the same offsets
      put_big_endian(message.data() + kRigIdOffset, kRigId);
      put_big_endian(message.data() + kBindingOffset, rig.stats().binding);
    }
    if (is_command_size(message.size()) && (flags & 4) != 0) key.sign(message.data(), message.size());
    rig.on_message("BELLOWS_IO_COMMAND", message.data(), message.size());
    t += 0.0005 * static_cast<double>(1 + (length % 16));  // up to 8 ms: timeouts happen too
    rig.service(nullptr, t);
    const ArmView view = view_of(arm);
    if (rig.stats().serving == 0 && !view.all_vented) __builtin_trap();
    // Checked every integration step; 10 mbar is far more than one step's rise.
    if (view.highest_chamber_Pa > ceiling_Pa + 1e3) __builtin_trap();
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size < 1) return 0;
  static const bellows::Configuration config;
  static const bellows::PneumaticChainParameters arm2 =
      bellows::pneumatic_chain_of(config.plant, bellows::ArmParameters{"arm2"});
  std::array<std::uint8_t, bellows::kLcmKeyBytes> key_bytes{};
  key_bytes.fill(0x5a);
  const bellows::LcmKey key(key_bytes);
  const std::uint8_t flags = data[0];

  bellows::RigServerParameters params;
  params.period_s = config.timing.tick_s;
  params.command_timeout_s = config.lcm.rig_timeout_s;
  params.seq_window = config.lcm.seq_window;
  params.limits = bellows::RigLimits::from(config);
  if ((flags & 1) != 0) params.key = key;
  const double ceiling_Pa = params.limits.pressure_ceiling_bar * 1e5;
  if ((flags & 8) != 0) {
    bellows::SimulatedArmChain arm(arm2, 1);
    bellows::RigServer rig(arm, arm.joints(), arm2.chain.integration_step_s, params, kRigId);
    serve(arm, rig, ceiling_Pa, key, flags, data, size);
  } else {
    bellows::SimulatedArm arm(config.plant, 1);
    bellows::RigServer rig(arm, params, kRigId);
    serve(arm, rig, ceiling_Pa, key, flags, data, size);
  }
  return 0;
}
