#include "devices/lcm_io_messages.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

#include "engine/base/errors.hpp"

namespace bellows {
namespace {

std::int64_t fingerprint(const void* data, std::size_t size) {
  if (data == nullptr || size < 8) return 0;
  return static_cast<std::int64_t>(detail::read_big_endian(static_cast<const std::uint8_t*>(data), 8));
}

bool row_zero(const double* values, int count) {
  return std::all_of(values, values + count, [](double v) { return v == 0.0; });
}

bool duty_ok(double duty) { return std::isfinite(duty) && duty >= 0.0 && duty <= 1.0; }

void check_joint_count(const char* what, int joints) {
  if (!valid_joint_count(joints)) {
    throw InputError(std::string(what) + " for " + std::to_string(joints) + " joints: the LCM messages carry 1 to " +
                     std::to_string(kMaxJoints));
  }
}

}  // namespace

namespace {

// A message of either kind, by its fingerprint: today's one-joint message is widened.
template <typename OneJoint, typename Joints>
DecodeStatus decode_either(const void* data, std::size_t size, Joints& out, const LcmKey* key) {
  if (fingerprint(data, size) == OneJoint::getHash()) {
    OneJoint one{};
    const DecodeStatus status = decode_checked(data, size, one, key);
    if (status == DecodeStatus::kOk) out = widen(one);
    return status;
  }
  return decode_checked(data, size, out, key);
}

}  // namespace

DecodeStatus decode_io_state(const void* data, std::size_t size, io_joints_state_t& out, const LcmKey* key) {
  return decode_either<io_state_t>(data, size, out, key);
}

DecodeStatus decode_io_command(const void* data, std::size_t size, io_joints_command_t& out, const LcmKey* key) {
  return decode_either<io_command_t>(data, size, out, key);
}

std::size_t encode_io_state(const io_joints_state_t& state, const LcmKey& key, std::vector<std::uint8_t>& buffer) {
  return state.joint_count == 1 ? encode_signed(narrow(state), key, buffer) : encode_signed(state, key, buffer);
}

std::size_t encode_io_command(const io_joints_command_t& command, const LcmKey& key,
                              std::vector<std::uint8_t>& buffer) {
  return command.joint_count == 1 ? encode_signed(narrow(command), key, buffer) : encode_signed(command, key, buffer);
}

std::size_t max_io_message_bytes() {
  return std::max({detail::fixed_size<io_state_t>(), detail::fixed_size<io_command_t>(),
                   detail::fixed_size<io_joints_state_t>(), detail::fixed_size<io_joints_command_t>()});
}

namespace {

// The fields the one-joint and the joint messages share, listed once for both directions.
template <typename From, typename To>
void copy_state_header(const From& from, To& to) {
  to.rig_id = from.rig_id;
  to.seq = from.seq;
  to.binding = from.binding;
  to.session_id = from.session_id;
  to.command_seq = from.command_seq;
  to.utime = from.utime;
  to.time_s = from.time_s;
  to.supply_bar = from.supply_bar;
  to.temperature_K = from.temperature_K;
  to.fault_bits = from.fault_bits;
  to.foreign_commands = from.foreign_commands;
  to.unauthenticated_commands = from.unauthenticated_commands;
}

template <typename From, typename To>
void copy_command_header(const From& from, To& to) {
  to.session_id = from.session_id;
  to.seq = from.seq;
  to.utime = from.utime;
  to.rig_id = from.rig_id;
  to.binding = from.binding;
  to.armed = from.armed;
}

}  // namespace

io_joints_state_t widen(const io_state_t& s) {
  io_joints_state_t w{};
  copy_state_header(s, w);
  w.joint_count = 1;
  w.angle_rad[0] = s.angle_rad;
  for (int i = 0; i < kActuatorCount; ++i) w.chamber_bar[0][i] = s.chamber_bar[i];
  return w;
}

io_joints_command_t widen(const io_command_t& c) {
  io_joints_command_t w{};
  copy_command_header(c, w);
  w.joint_count = 1;
  for (int i = 0; i < kActuatorCount; ++i) {
    w.inlet_duty[0][i] = c.inlet_duty[i];
    w.outlet_duty[0][i] = c.outlet_duty[i];
  }
  return w;
}

io_state_t narrow(const io_joints_state_t& state) {
  io_state_t s{};
  copy_state_header(state, s);
  s.angle_rad = state.angle_rad[0];
  for (int i = 0; i < kActuatorCount; ++i) s.chamber_bar[i] = state.chamber_bar[0][i];
  return s;
}

io_command_t narrow(const io_joints_command_t& command) {
  io_command_t c{};
  copy_command_header(command, c);
  for (int i = 0; i < kActuatorCount; ++i) {
    c.inlet_duty[i] = command.inlet_duty[0][i];
    c.outlet_duty[i] = command.outlet_duty[0][i];
  }
  return c;
}

bool valid_command(const io_joints_command_t& c) {
  if (c.session_id == 0 || c.seq <= 0 || !valid_joint_count(c.joint_count)) return false;
  for (int j = 0; j < kMaxJoints; ++j) {
    const bool used = j < c.joint_count;
    for (int i = 0; i < kActuatorCount; ++i) {
      for (double duty : {c.inlet_duty[j][i], c.outlet_duty[j][i]}) {
        if (used ? !duty_ok(duty) : duty != 0.0) return false;
      }
    }
  }
  return true;
}

bool valid_state(const io_joints_state_t& s) {
  if (s.rig_id == 0 || s.seq <= 0 || s.command_seq < 0 || s.session_id < 0 || !std::isfinite(s.time_s)) return false;
  if (!valid_joint_count(s.joint_count)) return false;
  for (int j = s.joint_count; j < kMaxJoints; ++j) {
    if (s.angle_rad[j] != 0.0 || !row_zero(s.chamber_bar[j], kActuatorCount)) return false;
  }
  return true;
}

bool valid_rig_limits(const io_rig_limits_t& l) {
  const auto positive = [](double x) { return std::isfinite(x) && x > 0.0; };
  return l.rig_id != 0 && l.seq > 0 && valid_joint_count(l.joint_count) && positive(l.period_s) &&
         positive(l.command_timeout_s) && positive(l.pressure_ceiling_bar) && positive(l.angle_limit_rad) &&
         l.angle_limit_rad <= std::numbers::pi;
}

ValveCommand to_valves(const io_joints_command_t& c) {
  const int joints = std::clamp<int>(c.joint_count, 1, kMaxJoints);
  if (!c.armed) return ValveCommand::vented(joints);
  ValveCommand valves = ValveCommand::vented(joints);  // rows beyond the arm stay vented
  for (int j = 0; j < joints; ++j) {
    JointValves& v = valves.joint[static_cast<std::size_t>(j)];
    for (int i = 0; i < kActuatorCount; ++i) {
      v.inlet_duty[i] = c.inlet_duty[j][i];
      v.outlet_duty[i] = c.outlet_duty[j][i];
    }
  }
  return valves;
}

void fill_command(const ValveCommand& valves, bool armed, io_joints_command_t& c) {
  check_joint_count("a valve command", valves.joint_count);
  c.armed = armed;
  c.joint_count = static_cast<std::int8_t>(valves.joint_count);
  for (int j = 0; j < kMaxJoints; ++j) {
    const bool used = j < valves.joint_count;
    for (int i = 0; i < kActuatorCount; ++i) {
      c.inlet_duty[j][i] = used ? valves.joint[static_cast<std::size_t>(j)].inlet_duty[i] : 0.0;
      c.outlet_duty[j][i] = used ? valves.joint[static_cast<std::size_t>(j)].outlet_duty[i] : 0.0;
    }
  }
}

SensorReading to_reading(const io_joints_state_t& s) {
  SensorReading reading;
  reading.time_s = s.time_s;
  reading.joint_count = std::clamp<int>(s.joint_count, 1, kMaxJoints);
  for (int j = 0; j < reading.joint_count; ++j) {
    JointReading& joint = reading.joint[static_cast<std::size_t>(j)];
    joint.angle_rad = s.angle_rad[j];
    for (int i = 0; i < kActuatorCount; ++i) joint.chamber_bar[i] = s.chamber_bar[j][i];
  }
  reading.supply_bar = s.supply_bar;
  reading.temperature_K = s.temperature_K;
  return reading;
}

void fill_state(const SensorReading& reading, io_joints_state_t& s) {
  check_joint_count("a reading", reading.joint_count);
  s.time_s = reading.time_s;
  s.joint_count = static_cast<std::int8_t>(reading.joint_count);
  for (int j = 0; j < kMaxJoints; ++j) {
    const bool used = j < reading.joint_count;
    const JointReading& joint = reading.joint[static_cast<std::size_t>(j)];
    s.angle_rad[j] = used ? joint.angle_rad : 0.0;
    for (int i = 0; i < kActuatorCount; ++i) s.chamber_bar[j][i] = used ? joint.chamber_bar[i] : 0.0;
  }
  s.supply_bar = reading.supply_bar;
  s.temperature_K = reading.temperature_K;
}

std::string arm_joints_words(int joints) {
  return joints == 1 ? std::string("one joint (io_state_t / io_command_t)") : std::to_string(joints) + " joints";
}

}  // namespace bellows
