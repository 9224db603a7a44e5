// Authentication of the rig's I/O messages with a shared key ([lcm] key_file): HMAC-SHA256
// (libsodium's crypto_auth_hmacsha256) over every encoded byte of a message before its `mac` field,
// which is its last 32 bytes. Without a key nothing is signed or checked (the mac stays zero).
//
// What it protects and what not is in docs/lcm-protocol.md: a host without the key can neither
// forge nor alter a command or state; it can still replay one (sequence numbers, the rig's binding
// nonce and session ids make a replay useless), drop messages, or flood the bus.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <string>

namespace bellows {

inline constexpr std::size_t kLcmKeyBytes = 32;  // crypto_auth_hmacsha256_KEYBYTES
inline constexpr std::size_t kLcmMacBytes = 32;  // crypto_auth_hmacsha256_BYTES

class LcmKey {
 public:
  LcmKey() = default;  // no key: messages are neither signed nor checked
  explicit LcmKey(const std::array<std::uint8_t, kLcmKeyBytes>& bytes);

  bool present() const { return present_; }
  /// Writes the MAC of bytes [0, size - 32) into the last 32 bytes (zeros without a key).
  /// `size` must be at least 32.
  void sign(std::uint8_t* message, std::size_t size) const;
  /// Whether the last 32 bytes are the MAC of the bytes before them (always true without a key).
  bool verify(const std::uint8_t* message, std::size_t size) const;

 private:
  std::array<std::uint8_t, kLcmKeyBytes> key_{};
  bool present_ = false;
};

/// Reads a key file: exactly 32 bytes (`head -c 32 /dev/urandom > rig.key; chmod 600 rig.key`), a
/// regular file no one but its owner and group may read. A relative `path` is taken relative to
/// `relative_to` (the configuration file's directory; empty: the working directory). An empty
/// `path` is no key. Throws InputError with one line for anything else.
LcmKey load_lcm_key(const std::string& path, const std::filesystem::path& relative_to = {});

}  // namespace bellows
