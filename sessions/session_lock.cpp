#include "sessions/session_lock.hpp"

#include <fcntl.h>
#include <sys/file.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <ctime>
#include <utility>

#include "engine/base/errors.hpp"
#include "engine/base/printable_text.hpp"
#include "sessions/file_access.hpp"

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
  return holder.empty() ? "another process" : printable(holder);  // anyone may have written it
}

}  // namespace

SessionLock::SessionLock(const DirectoryHandle& directory, const std::string& purpose) {
  const std::string session = "session " + printable(directory.path().string());
  try {
    fd_ = open_regular_file_at(directory, kFileName, O_RDWR | O_CREAT, /*single_link=*/true)->release();
  } catch (const InputError& error) {
    throw InputError(session + ": " + error.what());
  }
  if (::flock(fd_, LOCK_EX | LOCK_NB) != 0) {
    const int error_number = errno;
    const std::string holder = error_number == EWOULDBLOCK ? read_holder(fd_) : std::string();
    ::close(fd_);
    fd_ = -1;
    if (error_number == EWOULDBLOCK) {
      throw InputError(session + " is in use by " + holder + "; two processes never write the same session");
    }
    throw_file_error(session + ": cannot lock " + kFileName, error_number);
  }
  // Best effort: the line only serves the message another process prints.
  const std::string line = holder_line(purpose);
  if (::ftruncate(fd_, 0) == 0) {
    [[maybe_unused]] const ssize_t written = ::pwrite(fd_, line.data(), line.size(), 0);
  }
}

std::optional<std::string> SessionLock::holder(const DirectoryHandle& directory) {
  std::optional<FileDescriptor> fd;
  try {
    fd = open_regular_file_at(directory, kFileName, O_RDONLY);
  } catch (const InputError&) {
    return std::nullopt;  // not a lock file: nobody holds it (taking the lock says what is wrong)
  }
  if (!fd) return std::nullopt;
  std::optional<std::string> holder;
  if (::flock(fd->get(), LOCK_SH | LOCK_NB) != 0) {
    if (errno == EWOULDBLOCK) holder = read_holder(fd->get());
  }
  return holder;  // closing the descriptor drops the shared lock, if it was granted
}

std::optional<std::string> SessionLock::holder(const std::filesystem::path& directory) {
  try {
    return holder(DirectoryHandle::open(directory));
  } catch (const InputError&) {
    return std::nullopt;
  }
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
