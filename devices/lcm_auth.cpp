#include "devices/lcm_auth.hpp"

#include <fcntl.h>
#include <sodium.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>

#include "engine/base/errors.hpp"

namespace bellows {
namespace {

static_assert(kLcmKeyBytes == crypto_auth_hmacsha256_KEYBYTES);
static_assert(kLcmMacBytes == crypto_auth_hmacsha256_BYTES);

void init_sodium() {
  static const int status = sodium_init();  // thread-safe, idempotent; < 0 only without entropy
  if (status < 0) throw EnvironmentError("libsodium cannot be initialized");
}

/// Closes a file descriptor when it goes out of scope.
struct FdCloser {
  int fd;
  ~FdCloser() {
    if (fd >= 0) ::close(fd);
  }
};

}  // namespace

LcmKey::LcmKey(const std::array<std::uint8_t, kLcmKeyBytes>& bytes) : key_(bytes), present_(true) { init_sodium(); }

void LcmKey::sign(std::uint8_t* message, std::size_t size) const {
  std::uint8_t* mac = message + size - kLcmMacBytes;
  if (!present_) {
    std::memset(mac, 0, kLcmMacBytes);
    return;
  }
  crypto_auth_hmacsha256(mac, message, size - kLcmMacBytes, key_.data());
}

bool LcmKey::verify(const std::uint8_t* message, std::size_t size) const {
  if (!present_) return true;
  if (size < kLcmMacBytes) return false;
  return crypto_auth_hmacsha256_verify(message + size - kLcmMacBytes, message, size - kLcmMacBytes, key_.data()) == 0;
}

LcmKey load_lcm_key(const std::string& path, const std::filesystem::path& relative_to) {
  if (path.empty()) return {};
  std::filesystem::path file(path);
  if (file.is_relative() && !relative_to.empty()) file = relative_to / file;
  const std::string where = "[lcm] key_file '" + file.string() + "'";
  const int fd = ::open(file.c_str(), O_RDONLY | O_CLOEXEC | O_NONBLOCK | O_NOCTTY);  // a FIFO must not hang us
  if (fd < 0) throw InputError(where + ": cannot be opened (" + std::strerror(errno) + ")");
  const FdCloser closer{fd};
  struct stat info {};
  if (::fstat(fd, &info) != 0) throw InputError(where + ": cannot be examined (" + std::strerror(errno) + ")");
  if (!S_ISREG(info.st_mode)) throw InputError(where + ": not a regular file");
  if ((info.st_mode & (S_IROTH | S_IWOTH)) != 0) {
    throw InputError(where + ": readable or writable by everyone; a shared key must stay secret (chmod 600)");
  }
  if (info.st_size != static_cast<off_t>(kLcmKeyBytes)) {
    throw InputError(where + ": " + std::to_string(info.st_size) + " bytes; a key is exactly " +
                     std::to_string(kLcmKeyBytes) + " bytes (head -c 32 /dev/urandom > FILE)");
  }
  std::array<std::uint8_t, kLcmKeyBytes> bytes{};
  std::size_t got = 0;
  while (got < bytes.size()) {
    const ssize_t n = ::read(fd, bytes.data() + got, bytes.size() - got);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) throw InputError(where + ": cannot be read whole");
    got += static_cast<std::size_t>(n);
  }
  init_sodium();
  const LcmKey key(bytes);
  sodium_memzero(bytes.data(), bytes.size());
  return key;
}

}  // namespace bellows
