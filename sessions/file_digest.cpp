#include "sessions/file_digest.hpp"

#include <sodium.h>

#include <stdexcept>

namespace bellows {

std::string sha256_hex(std::string_view bytes) {
  static const int initialized = sodium_init();  // once, thread-safe; 1 = already initialized
  if (initialized < 0) throw std::runtime_error("libsodium cannot be initialized");
  unsigned char digest[crypto_hash_sha256_BYTES];
  crypto_hash_sha256(digest, reinterpret_cast<const unsigned char*>(bytes.data()), bytes.size());
  char hex[crypto_hash_sha256_BYTES * 2 + 1];
  sodium_bin2hex(hex, sizeof hex, digest, sizeof digest);
  return std::string(hex, crypto_hash_sha256_BYTES * 2);
}

bool is_sha256_hex(std::string_view text) {
  if (text.size() != crypto_hash_sha256_BYTES * 2) return false;
  for (char c : text) {
    if (!((c >= '0' && c <= '9') || (c >= 'a' && c <= 'f'))) return false;
  }
  return true;
}

}  // namespace bellows
