#include "sessions/session_lock.hpp"

#include <fcntl.h>
#include <sys/file.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <ctime>
#include <utility>

#include "engine/errors.hpp"

namespace bellows {
namespace {

std::string holder_line(const std::string& purpose) {
  char host[256] = "unknown host";
  ::gethostname(host, sizeof host - 1);
  host[sizeof host - 1] = '\0';
  char since[32] = "";
  const std::time_t now = std::time(nullptr);
  std::tm utc{};
  ::gmtime_r(&now, &utc);
  std::strftime(since, sizeof since, "%Y-%m-%dT%H:%M:%SZ", &utc);
  return purpose + " (pid " + std::to_string(::getpid()) + " on " + host + ", since " + since + ")\n";
}

std::string read_holder(int fd) {
  char buffer[512];
  const ssize_t got = ::pread(fd, buffer, sizeof buffer - 1, 0);
  std::string holder(buffer, got > 0 ? static_cast<std::size_t>(got) : 0);
  while (!holder.empty() && (holder.back() == '\n' || holder.back() == '\r')) holder.pop_back();
  return holder.empty() ? "another process" : holder;
}

}  // namespace

SessionLock::SessionLock(const std::filesystem::path& directory, const std::string& purpose) {
  const std::filesystem::path path = directory / kFileName;
  fd_ = ::open(path.c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0644);
  if (fd_ < 0) throw InputError("session " + directory.string() + ": cannot open " + path.string() + ": " + std::strerror(errno));
  if (::flock(fd_, LOCK_EX | LOCK_NB) != 0) {
    const int error_number = errno;
    const std::string holder = error_number == EWOULDBLOCK ? read_holder(fd_) : std::string();
    ::close(fd_);
    fd_ = -1;
    if (error_number == EWOULDBLOCK) {
      throw InputError("session " + directory.string() + " is in use by " + holder +
                       "; two processes never write the same session");
    }
    throw InputError("session " + directory.string() + ": cannot lock " + path.string() + ": " + std::strerror(error_number));
  }
  // Best effort: the line only serves the message another process prints.
  const std::string line = holder_line(purpose);
  if (::ftruncate(fd_, 0) == 0) {
    [[maybe_unused]] const ssize_t written = ::pwrite(fd_, line.data(), line.size(), 0);
  }
}

std::optional<std::string> SessionLock::holder(const std::filesystem::path& directory) {
  const int fd = ::open((directory / kFileName).c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0) return std::nullopt;
  std::optional<std::string> holder;
  if (::flock(fd, LOCK_SH | LOCK_NB) != 0) {
    if (errno == EWOULDBLOCK) holder = read_holder(fd);
  }
  ::close(fd);  // also drops the shared lock, if it was granted
  return holder;
}

SessionLock::~SessionLock() {
  if (fd_ >= 0) ::close(fd_);  // closing the last descriptor releases the flock
}

SessionLock::SessionLock(SessionLock&& other) noexcept : fd_(std::exchange(other.fd_, -1)) {}

SessionLock& SessionLock::operator=(SessionLock&& other) noexcept {
  if (this != &other) {
    if (fd_ >= 0) ::close(fd_);
    fd_ = std::exchange(other.fd_, -1);
  }
  return *this;
}

}  // namespace bellows
