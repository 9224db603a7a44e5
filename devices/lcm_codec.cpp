#include "devices/lcm_codec.hpp"

#include <sodium.h>

#include <climits>
#include <cmath>
#include <stdexcept>
#include <string>

#include "engine/base/errors.hpp"

namespace bellows {
namespace {

// io_command_t and io_state_t carry one joint's valves and sensors; several joints travel in
// io_joints_command_t and io_joints_state_t (devices/lcm_io_messages).
std::string single_joint_protocol(const char* what, int joints) {
  return std::string("io_command_t and io_state_t carry one joint: ") + what + " for " + std::to_string(joints) +
         " joints goes in io_joints_command_t / io_joints_state_t";
}

}  // namespace

const char* to_string(DecodeStatus status) {
  switch (status) {
    case DecodeStatus::kOk:
      return "ok";
    case DecodeStatus::kTruncated:
      return "truncated";
    case DecodeStatus::kWrongType:
      return "wrong-type";
    case DecodeStatus::kTooLarge:
      return "too-large";
    case DecodeStatus::kMalformed:
      return "malformed";
    case DecodeStatus::kOldVersion:
      return "old-version";
    case DecodeStatus::kUnauthenticated:
      return "unauthenticated";
  }
  return "?";
}

const char* explain(DecodeStatus status) {
  switch (status) {
    case DecodeStatus::kOk:
      return "accepted";
    case DecodeStatus::kTruncated:
      return "shorter than its type";
    case DecodeStatus::kWrongType:
      return "not of the expected type";
    case DecodeStatus::kTooLarge:
      return "longer than any valid message of its type";
    case DecodeStatus::kMalformed:
      return "malformed";
    case DecodeStatus::kOldVersion:
      return "of protocol version 1, which this bellows no longer speaks (update the sender: docs/lcm-protocol.md)";
    case DecodeStatus::kUnauthenticated:
      return "not signed with this [lcm] key_file (another sender, or a different key)";
  }
  return "?";
}

std::int64_t random_nonzero_id() {
  if (sodium_init() < 0) throw std::runtime_error("libsodium cannot be initialized");
  std::uint64_t id = 0;
  while (id == 0 || id > static_cast<std::uint64_t>(INT64_MAX)) {
    randombytes_buf(&id, sizeof id);
    id >>= 1;  // positive
  }
  return static_cast<std::int64_t>(id);
}

void ReceiveCounters::count(DecodeStatus status) {
  switch (status) {
    case DecodeStatus::kOk:
      return;  // accepted only once its values and order passed too
    case DecodeStatus::kTruncated:
      bump(truncated_);
      return;
    case DecodeStatus::kWrongType:
      bump(wrong_type_);
      return;
    case DecodeStatus::kTooLarge:
      bump(too_large_);
      return;
    case DecodeStatus::kMalformed:
      bump(malformed_);
      return;
    case DecodeStatus::kOldVersion:
      bump(old_version_);
      return;
    case DecodeStatus::kUnauthenticated:
      bump(unauthenticated_);
      return;
  }
}

ReceiveCounts ReceiveCounters::snapshot() const {
  constexpr auto relaxed = std::memory_order_relaxed;
  ReceiveCounts c;
  c.accepted = accepted_.load(relaxed);
  c.truncated = truncated_.load(relaxed);
  c.wrong_type = wrong_type_.load(relaxed);
  c.too_large = too_large_.load(relaxed);
  c.malformed = malformed_.load(relaxed);
  c.invalid = invalid_.load(relaxed);
  c.foreign = foreign_.load(relaxed);
  c.out_of_order = out_of_order_.load(relaxed);
  c.old_version = old_version_.load(relaxed);
  c.unauthenticated = unauthenticated_.load(relaxed);
  c.other_joints = other_joints_.load(relaxed);
  c.offers = offers_.load(relaxed);
  return c;
}

bool valid_command(const io_command_t& command) {
  if (command.session_id == 0 || command.seq <= 0) return false;
  for (int i = 0; i < kActuatorCount; ++i) {
    for (double duty : {command.inlet_duty[i], command.outlet_duty[i]}) {
      if (!std::isfinite(duty) || duty < 0.0 || duty > 1.0) return false;
    }
  }
  return true;
}

bool valid_state(const io_state_t& state) {
  return state.rig_id != 0 && state.seq > 0 && state.command_seq >= 0 && state.session_id >= 0 &&
         std::isfinite(state.time_s);
}

ValveCommand to_valves(const io_command_t& command) {
  if (!command.armed) return ValveCommand::vented();
  ValveCommand valves;  // one joint: what the message carries
  for (int i = 0; i < kActuatorCount; ++i) {
    valves.joint[0].inlet_duty[i] = command.inlet_duty[i];
    valves.joint[0].outlet_duty[i] = command.outlet_duty[i];
  }
  return valves;
}

void fill_command(const ValveCommand& valves, bool armed, io_command_t& command) {
  if (valves.joint_count != 1) throw InputError(single_joint_protocol("a valve command", valves.joint_count));
  command.armed = armed;
  for (int i = 0; i < kActuatorCount; ++i) {
    command.inlet_duty[i] = valves.joint[0].inlet_duty[i];
    command.outlet_duty[i] = valves.joint[0].outlet_duty[i];
  }
}

SensorReading to_reading(const io_state_t& state) {
  SensorReading reading;
  reading.time_s = state.time_s;
  reading.joint_count = 1;  // what the message carries
  reading.joint[0].angle_rad = state.angle_rad;
  for (int i = 0; i < kActuatorCount; ++i) reading.joint[0].chamber_bar[i] = state.chamber_bar[i];
  reading.supply_bar = state.supply_bar;
  reading.temperature_K = state.temperature_K;
  return reading;
}

void fill_state(const SensorReading& reading, io_state_t& state) {
  if (reading.joint_count != 1) throw InputError(single_joint_protocol("a reading", reading.joint_count));
  state.time_s = reading.time_s;
  state.angle_rad = reading.joint[0].angle_rad;
  for (int i = 0; i < kActuatorCount; ++i) state.chamber_bar[i] = reading.joint[0].chamber_bar[i];
  state.supply_bar = reading.supply_bar;
  state.temperature_K = reading.temperature_K;
}

}  // namespace bellows
