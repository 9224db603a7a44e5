// The I/O messages of an arm of J joints (docs/lcm-protocol.md). An arm of one joint speaks
// io_command_t / io_state_t exactly as before joints existed (byte for byte); an arm of several
// speaks io_joints_command_t / io_joints_state_t, the same fields with a joint count and a row per
// joint, on the same channels. Endpoints (LcmDevice, RigServer) work on the joints form only: a
// received message of either type is decoded and widened to it, and an outgoing one is narrowed to
// io_command_t / io_state_t when it has one joint. Whether the joint count is the endpoint's own is
// the endpoint's check (a valid message of another arm is counted as `other_joints`, with one line).
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "devices/lcm_codec.hpp"
#include "engine/base/joints.hpp"

namespace bellows {

static_assert(io_joints_state_t::MAX_JOINTS == kMaxJoints && io_joints_command_t::MAX_JOINTS == kMaxJoints,
              "the joint messages' rows are bellows' joint capacity");

/// io_state_t or io_joints_state_t, by fingerprint, checked as decode_checked does (a fingerprint of
/// neither is kWrongType, version 1's kOldVersion) and widened to the joints form.
DecodeStatus decode_io_state(const void* data, std::size_t size, io_joints_state_t& out, const LcmKey* key = nullptr);
/// The same for io_command_t or io_joints_command_t.
DecodeStatus decode_io_command(const void* data, std::size_t size, io_joints_command_t& out,
                               const LcmKey* key = nullptr);

/// Encodes and signs (encode_signed) as io_state_t when `state` has one joint, else io_joints_state_t.
std::size_t encode_io_state(const io_joints_state_t& state, const LcmKey& key, std::vector<std::uint8_t>& buffer);
std::size_t encode_io_command(const io_joints_command_t& command, const LcmKey& key, std::vector<std::uint8_t>& buffer);
/// The longest encoding of either I/O message (a send buffer sized once).
std::size_t max_io_message_bytes();

/// The one-joint message as the joints form (joint_count 1) and back (joint 1's row; the MAC is
/// not carried over: encoding signs anew).
io_joints_state_t widen(const io_state_t& state);
io_joints_command_t widen(const io_command_t& command);
io_state_t narrow(const io_joints_state_t& state);
io_command_t narrow(const io_joints_command_t& command);

/// A command a rig may consider: a session, a sequence number, a joint count in 1..MAX_JOINTS, every
/// duty of its joints finite in [0, 1] and every row beyond them zero (a row of the sender's
/// arm cannot hide there).
bool valid_command(const io_joints_command_t& command);
/// A state an engine may read: a rig, a sequence number, a finite rig time, a joint count in
/// 1..MAX_JOINTS and every row beyond it zero. Sensor values are the engine's guards' to judge.
bool valid_state(const io_joints_state_t& state);

/// Limits a rig may announce: a rig, a sequence number, a joint count in 1..MAX_JOINTS, every value
/// finite and positive, the angle range at most pi.
bool valid_rig_limits(const io_rig_limits_t& limits);

/// The duties of the command's joints when armed, else every joint vented.
ValveCommand to_valves(const io_joints_command_t& command);
/// Valves of 1..kMaxJoints joints (InputError otherwise) into `command`, rows beyond zeroed.
void fill_command(const ValveCommand& valves, bool armed, io_joints_command_t& command);
/// The sensor values of a state (time_s is the rig's; the device replaces it by its own clock).
SensorReading to_reading(const io_joints_state_t& state);
void fill_state(const SensorReading& reading, io_joints_state_t& state);

/// An arm's joint count for a line: "one joint (io_state_t / io_command_t)", "3 joints".
std::string arm_joints_words(int joints);

}  // namespace bellows
