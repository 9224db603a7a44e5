// Checked decoding of the bellows LCM messages. Nothing received is trusted: a message is used only
// when its size, fingerprint, lengths and values pass; whatever fails is counted by reason and
// dropped. LCM's generated decoders alone would allocate whatever a length field claims and turn a
// bad string length into an exception, so every size is bounded before they run.
#pragma once

#include <atomic>
#include <climits>
#include <cstddef>
#include <cstdint>
#include <exception>
#include <vector>

#include <bellows/engine_event_t.hpp>
#include <bellows/io_command_t.hpp>
#include <bellows/io_joints_command_t.hpp>
#include <bellows/io_joints_state_t.hpp>
#include <bellows/io_rig_limits_t.hpp>
#include <bellows/io_state_t.hpp>
#include <bellows/telemetry_joints_t.hpp>
#include <bellows/telemetry_t.hpp>
#include <bellows/trial_summary_t.hpp>
#include <bellows_v1/io_command_t.hpp>
#include <bellows_v1/io_state_t.hpp>

#include "devices/lcm_auth.hpp"
#include "engine/rt/single_writer_counter.hpp"

#include "engine/control/device.hpp"

namespace bellows {

enum class DecodeStatus : std::uint8_t {
  kOk,
  kTruncated,        // shorter than the message it claims to be
  kWrongType,        // fingerprint of another type (or of another version of this one)
  kTooLarge,         // longer than any valid message of the type
  kMalformed,        // lengths or contents that do not parse, or bytes left over
  kOldVersion,       // the fingerprint of an earlier protocol version of this type (lcmtypes/v1/)
  kUnauthenticated,  // the right shape, but its MAC does not match the key ([lcm] key_file)
};
const char* to_string(DecodeStatus status);

/// Limits on what a decoder accepts.
inline constexpr std::int32_t kMaxTrialSamples = 1 << 20;  // a trial summary's correction length
inline constexpr std::size_t kMaxEventBytes = 64 * 1024;   // an engine event, its text included

/// Received messages by outcome: plain numbers, for reports.
struct ReceiveCounts {
  std::uint64_t accepted = 0;
  std::uint64_t truncated = 0, wrong_type = 0, too_large = 0, malformed = 0;  // did not decode
  std::uint64_t invalid = 0;          // decoded, but values no valid sender sends
  std::uint64_t foreign = 0;          // another session (or rig) than the one served
  std::uint64_t out_of_order = 0;     // sequence number or time not after the last accepted one, or a jump
  std::uint64_t old_version = 0;      // an earlier protocol version's message
  std::uint64_t unauthenticated = 0;  // MAC missing or wrong (only with a key)
  std::uint64_t other_joints = 0;     // valid, but for an arm of another joint count than this one's
  // Not an error and not in ignored(): a free rig's offers (session 0), which every engine hears
  // before it binds (the engine's states only; a rig counts none).
  std::uint64_t offers = 0;
  std::uint64_t ignored() const {
    return truncated + wrong_type + too_large + malformed + invalid + foreign + out_of_order + old_version +
           unauthenticated + other_joints;
  }
};

/// The same, counted by the one thread that receives and read by any other.
class ReceiveCounters {
 public:
  void count(DecodeStatus status);
  void accepted() { bump(accepted_); }
  void invalid() { bump(invalid_); }
  void foreign() { bump(foreign_); }
  void out_of_order() { bump(out_of_order_); }
  void other_joints() { bump(other_joints_); }
  void offer() { bump(offers_); }
  ReceiveCounts snapshot() const;

 private:
  std::atomic<std::uint64_t> accepted_{0}, truncated_{0}, wrong_type_{0}, too_large_{0}, malformed_{0};
  std::atomic<std::uint64_t> invalid_{0}, foreign_{0}, out_of_order_{0}, old_version_{0}, unauthenticated_{0};
  std::atomic<std::uint64_t> other_joints_{0}, offers_{0};
};

namespace detail {

inline std::uint64_t read_big_endian(const std::uint8_t* p, int bytes) {
  std::uint64_t value = 0;
  for (int i = 0; i < bytes; ++i) value = (value << 8) | p[i];
  return value;
}

/// The fingerprint the previous protocol version gave a type (0: none).
template <typename Message>
std::int64_t previous_version_hash() {
  return 0;
}
template <>
inline std::int64_t previous_version_hash<io_command_t>() {
  return bellows_v1::io_command_t::getHash();
}
template <>
inline std::int64_t previous_version_hash<io_state_t>() {
  return bellows_v1::io_state_t::getHash();
}
// A version-1 peer is refused as such by an arm of several joints too.
template <>
inline std::int64_t previous_version_hash<io_joints_command_t>() {
  return bellows_v1::io_command_t::getHash();
}
template <>
inline std::int64_t previous_version_hash<io_joints_state_t>() {
  return bellows_v1::io_state_t::getHash();
}

/// Encoded size of a message type with no variable-length field.
template <typename Message>
std::size_t fixed_size() {
  static const std::size_t size = static_cast<std::size_t>(Message().getEncodedSize());
  return size;
}

/// The sizes a message of each type may have, given its bytes (at least the 8-byte fingerprint).
struct SizeRange {
  std::size_t min = 0, max = 0;
  DecodeStatus status = DecodeStatus::kOk;  // set when the bytes already tell it is bad
};
inline SizeRange size_range(const io_command_t&, const std::uint8_t*, std::size_t) {
  return {fixed_size<io_command_t>(), fixed_size<io_command_t>()};
}
inline SizeRange size_range(const io_state_t&, const std::uint8_t*, std::size_t) {
  return {fixed_size<io_state_t>(), fixed_size<io_state_t>()};
}
inline SizeRange size_range(const io_joints_command_t&, const std::uint8_t*, std::size_t) {
  return {fixed_size<io_joints_command_t>(), fixed_size<io_joints_command_t>()};
}
inline SizeRange size_range(const io_joints_state_t&, const std::uint8_t*, std::size_t) {
  return {fixed_size<io_joints_state_t>(), fixed_size<io_joints_state_t>()};
}
inline SizeRange size_range(const io_rig_limits_t&, const std::uint8_t*, std::size_t) {
  return {fixed_size<io_rig_limits_t>(), fixed_size<io_rig_limits_t>()};
}
inline SizeRange size_range(const telemetry_t&, const std::uint8_t*, std::size_t) {
  return {fixed_size<telemetry_t>(), fixed_size<telemetry_t>()};
}
inline SizeRange size_range(const telemetry_joints_t&, const std::uint8_t*, std::size_t) {
  return {fixed_size<telemetry_joints_t>(), fixed_size<telemetry_joints_t>()};
}
inline SizeRange size_range(const engine_event_t&, const std::uint8_t*, std::size_t) {
  return {fixed_size<engine_event_t>(), kMaxEventBytes};  // the empty text is the shortest
}
/// `samples` comes first after the fingerprint, so the exact size is known before decoding.
inline SizeRange size_range(const trial_summary_t&, const std::uint8_t* bytes, std::size_t size) {
  const std::size_t base = fixed_size<trial_summary_t>();
  if (size < 12) return {base, base, DecodeStatus::kTruncated};
  const auto samples = static_cast<std::int32_t>(static_cast<std::uint32_t>(read_big_endian(bytes + 8, 4)));
  if (samples < 0) return {base, base, DecodeStatus::kMalformed};
  if (samples > kMaxTrialSamples) return {base, base, DecodeStatus::kTooLarge};
  const std::size_t exact = base + 8 * static_cast<std::size_t>(samples);
  return {exact, exact};
}

}  // namespace detail

/// Decodes `size` bytes into `out` (only meaningful when the result is kOk). With a `key` (the I/O
/// messages), the MAC in the last 32 bytes is checked before anything is decoded.
template <typename Message>
DecodeStatus decode_checked(const void* data, std::size_t size, Message& out, const LcmKey* key = nullptr) {
  const auto* bytes = static_cast<const std::uint8_t*>(data);
  if (data == nullptr || size < 8) return DecodeStatus::kTruncated;
  const auto hash = static_cast<std::int64_t>(detail::read_big_endian(bytes, 8));
  if (hash != Message::getHash()) {
    const std::int64_t previous = detail::previous_version_hash<Message>();
    return previous != 0 && hash == previous ? DecodeStatus::kOldVersion : DecodeStatus::kWrongType;
  }
  const detail::SizeRange range = detail::size_range(out, bytes, size);
  if (range.status != DecodeStatus::kOk) return range.status;
  if (size < range.min) return DecodeStatus::kTruncated;
  if (size > range.max || size > static_cast<std::size_t>(INT_MAX)) return DecodeStatus::kTooLarge;
  if (key != nullptr && !key->verify(bytes, size)) return DecodeStatus::kUnauthenticated;
  try {
    const int used = out.decode(data, 0, static_cast<int>(size));
    if (used < 0) return DecodeStatus::kMalformed;
    if (static_cast<std::size_t>(used) != size) return DecodeStatus::kMalformed;  // bytes left over
  } catch (const std::exception&) {                                               // e.g. a negative string length
    return DecodeStatus::kMalformed;
  }
  return DecodeStatus::kOk;
}

/// Encodes `message` into `buffer` (grown when needed; reused, so steady publishing allocates
/// nothing). Returns the encoded size.
template <typename Message>
std::size_t encode_into(const Message& message, std::vector<std::uint8_t>& buffer) {
  const int size = message.getEncodedSize();
  if (buffer.size() < static_cast<std::size_t>(size)) buffer.resize(static_cast<std::size_t>(size));
  message.encode(buffer.data(), 0, size);
  return static_cast<std::size_t>(size);
}

/// The same for the I/O messages, whose last 32 bytes are the MAC: signed with `key` (zeros without).
template <typename Message>
std::size_t encode_signed(const Message& message, const LcmKey& key, std::vector<std::uint8_t>& buffer) {
  static_assert(sizeof(message.mac) == kLcmMacBytes, "the MAC is the message's last field");
  const std::size_t size = encode_into(message, buffer);
  key.sign(buffer.data(), size);
  return size;
}

// ---- the I/O protocol's values ----

/// Why a status was refused, for a log line ("an old protocol version (update the sender)", ...).
const char* explain(DecodeStatus status);

/// A random nonzero 64-bit id (sessions, rigs, binding offers), from libsodium's generator.
std::int64_t random_nonzero_id();

/// A command a rig may consider: a session, a sequence number, every duty cycle finite in [0, 1].
bool valid_command(const io_command_t& command);
/// A state an engine may read: a rig, a sequence number, a finite rig time. Sensor values are not
/// judged here: a NaN or an absurd pressure reaches the engine's guards, which fault on it.
bool valid_state(const io_state_t& state);

/// What the rig applies: the duties when armed, else the vented state (one joint: the messages
/// carry one). fill_command and fill_state throw InputError for a command or reading of another
/// joint count than one: these messages cannot carry it (devices/lcm_io_messages: the messages of
/// an arm of several joints, which endpoints use).
ValveCommand to_valves(const io_command_t& command);
void fill_command(const ValveCommand& valves, bool armed, io_command_t& command);
/// The sensor values of a state (time_s is the rig's; the device replaces it by its own clock).
SensorReading to_reading(const io_state_t& state);
void fill_state(const SensorReading& reading, io_state_t& state);

}  // namespace bellows
