#include "sessions/atomic_file.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <utility>

#include "engine/errors.hpp"

namespace bellows {
namespace {

constexpr std::string_view kTemporaryMarker = ".tmp-";

[[noreturn]] void fail(const std::string& what, const std::filesystem::path& path, int error_number) {
  throw InputError("cannot " + what + " " + path.string() + ": " + std::strerror(error_number));
}

/// Closes a descriptor on every path out of a scope.
class FileDescriptor {
 public:
  explicit FileDescriptor(int fd) : fd_(fd) {}
  ~FileDescriptor() {
    if (fd_ >= 0) ::close(fd_);
  }
  FileDescriptor(const FileDescriptor&) = delete;
  FileDescriptor& operator=(const FileDescriptor&) = delete;
  int get() const { return fd_; }
  int release() { return std::exchange(fd_, -1); }

 private:
  int fd_;
};

}  // namespace

std::filesystem::path temporary_path_for(const std::filesystem::path& path) {
  // Hidden, and unique per process: a crashed writer's leftovers never collide with a live one.
  std::string name = ".";  // built by appends: GCC 12 warns falsely (-Wrestrict) on "." + string
  name.append(path.filename().string()).append(kTemporaryMarker).append(std::to_string(::getpid()));
  return path.parent_path() / name;
}

void write_file_atomic(const std::filesystem::path& path, std::string_view contents, DirectorySync directory_sync) {
  const std::filesystem::path directory = path.parent_path().empty() ? "." : path.parent_path();
  const std::filesystem::path temporary = temporary_path_for(path);
  FileDescriptor fd(::open(temporary.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644));
  if (fd.get() < 0) fail("create", temporary, errno);
  const char* data = contents.data();
  std::size_t left = contents.size();
  while (left > 0) {
    const ssize_t written = ::write(fd.get(), data, left);
    if (written < 0) {
      if (errno == EINTR) continue;
      const int error_number = errno;
      ::unlink(temporary.c_str());
      fail("write", temporary, error_number);
    }
    data += written;
    left -= static_cast<std::size_t>(written);
  }
  if (::fsync(fd.get()) != 0) {
    const int error_number = errno;
    ::unlink(temporary.c_str());
    fail("flush", temporary, error_number);
  }
  if (::close(fd.release()) != 0) fail("close", temporary, errno);
  if (::rename(temporary.c_str(), path.c_str()) != 0) {
    const int error_number = errno;
    ::unlink(temporary.c_str());
    fail("rename a file to", path, error_number);
  }
  if (directory_sync == DirectorySync::kNow) sync_directory(directory);
}

void sync_directory(const std::filesystem::path& directory) {
  FileDescriptor fd(::open(directory.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC));
  if (fd.get() < 0) fail("open directory", directory, errno);
  if (::fsync(fd.get()) != 0) fail("flush directory", directory, errno);
}

std::string read_file(const std::filesystem::path& path) {
  FileDescriptor fd(::open(path.c_str(), O_RDONLY | O_CLOEXEC));
  if (fd.get() < 0) fail("read", path, errno);
  std::string contents;
  struct stat info {};
  if (::fstat(fd.get(), &info) == 0 && info.st_size > 0) contents.reserve(static_cast<std::size_t>(info.st_size));
  char buffer[1 << 16];
  for (;;) {
    const ssize_t got = ::read(fd.get(), buffer, sizeof buffer);
    if (got < 0) {
      if (errno == EINTR) continue;
      fail("read", path, errno);
    }
    if (got == 0) break;
    contents.append(buffer, static_cast<std::size_t>(got));
  }
  return contents;
}

bool is_temporary_file_name(const std::string& file_name) {
  return !file_name.empty() && file_name.front() == '.' && file_name.find(kTemporaryMarker) != std::string::npos;
}

void remove_temporary_files(const std::filesystem::path& directory) {
  std::error_code error;
  for (const auto& entry : std::filesystem::directory_iterator(directory, error)) {
    if (is_temporary_file_name(entry.path().filename().string())) std::filesystem::remove(entry.path(), error);
  }
}

}  // namespace bellows
