#include "sessions/file_access.hpp"

#include <dirent.h>
#include <sys/random.h>
#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <utility>
#include <vector>

#include "engine/base/errors.hpp"
#include "engine/base/printable_text.hpp"
#include "sessions/atomic_file.hpp"

namespace bellows {

namespace fs = std::filesystem;

bool is_inside(const fs::path& path, const fs::path& directory) {
  std::error_code error;
  const fs::path inner = fs::weakly_canonical(fs::absolute(path), error);
  const fs::path outer = fs::weakly_canonical(fs::absolute(directory), error);
  if (error) return false;
  const fs::path relative = inner.lexically_relative(outer);
  return !relative.empty() && *relative.begin() != "..";
}

bool is_environment_failure(int error_number) {
  switch (error_number) {
    case ENOSPC:
    case EDQUOT:
    case EROFS:
    case EIO:
    case EFBIG:
    case ENOMEM:
    case EMFILE:
    case ENFILE:
    case ENOBUFS:
    case ESTALE:
    case ENOLCK:
      return true;
    default:
      return false;
  }
}

void throw_file_error(const std::string& message, int error_number) {
  const std::string line = message + ": " + std::strerror(error_number);
  if (is_environment_failure(error_number)) throw EnvironmentError(line);
  throw InputError(line);
}

namespace {

std::string shown(const fs::path& path) { return printable(path.string(), kPrintableField); }

/// Why opening `name` failed, in words an operator can act on.
std::string open_failure(int error_number) {
  if (error_number == ELOOP)
    return "is a symbolic link; a session's files must be inside it, so links are never followed";
  if (error_number == ENOTDIR) return "is not a directory";
  return std::strerror(error_number);
}

/// Reads the whole descriptor, refusing more than `max_bytes` (the size may change while reading).
std::string read_bounded(int fd, std::size_t max_bytes, const std::string& what) {
  struct stat info {};
  if (::fstat(fd, &info) != 0) throw_file_error(what, errno);
  if (!S_ISREG(info.st_mode)) throw InputError(what + " is " + file_type_name(info.st_mode) + ", not a regular file");
  const auto too_large = [&](std::size_t size) {
    return InputError(what + " is " + std::to_string(size) + " bytes, more than the " + std::to_string(max_bytes) +
                      " its format allows");
  };
  if (static_cast<std::uintmax_t>(info.st_size) > max_bytes) throw too_large(static_cast<std::size_t>(info.st_size));
  std::string contents;
  contents.reserve(static_cast<std::size_t>(info.st_size));
  char buffer[1 << 16];
  for (;;) {
    const ssize_t got = ::read(fd, buffer, sizeof buffer);
    if (got < 0) {
      if (errno == EINTR) continue;
      throw_file_error(what, errno);
    }
    if (got == 0) break;
    contents.append(buffer, static_cast<std::size_t>(got));
    if (contents.size() > max_bytes) throw too_large(contents.size());
  }
  return contents;
}

}  // namespace

FileDescriptor::~FileDescriptor() {
  if (fd_ >= 0) ::close(fd_);
}

FileDescriptor::FileDescriptor(FileDescriptor&& other) noexcept : fd_(std::exchange(other.fd_, -1)) {}

FileDescriptor& FileDescriptor::operator=(FileDescriptor&& other) noexcept {
  if (this != &other) {
    if (fd_ >= 0) ::close(fd_);
    fd_ = std::exchange(other.fd_, -1);
  }
  return *this;
}

int FileDescriptor::release() { return std::exchange(fd_, -1); }

std::string file_type_name(unsigned mode) {
  switch (mode & S_IFMT) {
    case S_IFREG:
      return "a regular file";
    case S_IFDIR:
      return "a directory";
    case S_IFLNK:
      return "a symbolic link";
    case S_IFIFO:
      return "a FIFO";
    case S_IFSOCK:
      return "a socket";
    case S_IFCHR:
      return "a character device";
    case S_IFBLK:
      return "a block device";
    default:
      return "a special file";
  }
}

DirectoryHandle DirectoryHandle::open(const fs::path& path) {
  FileDescriptor fd(::open(path.c_str(), O_RDONLY | O_DIRECTORY | O_NONBLOCK | O_CLOEXEC));
  if (fd.get() < 0) {
    const int error_number = errno;
    throw InputError(shown(path) + ": " + (error_number == ENOENT ? "no such directory" : open_failure(error_number)));
  }
  return DirectoryHandle(std::move(fd), path);
}

std::optional<DirectoryHandle> DirectoryHandle::subdirectory(const std::string& name) const {
  FileDescriptor fd(::openat(fd_.get(), name.c_str(), O_RDONLY | O_DIRECTORY | O_NOFOLLOW | O_CLOEXEC));
  if (fd.get() < 0) {
    const int error_number = errno;
    if (error_number == ENOENT) return std::nullopt;
    // ENOTDIR for a file, ELOOP for a link: say which.
    struct stat info {};
    const std::string what =
        ::fstatat(fd_.get(), name.c_str(), &info, AT_SYMLINK_NOFOLLOW) == 0 && !S_ISDIR(info.st_mode)
            ? "is " + file_type_name(info.st_mode) + ", not a directory" +
                  (S_ISLNK(info.st_mode) ? " (links are never followed)" : "")
            : open_failure(error_number);
    throw InputError(name + " " + what);
  }
  return DirectoryHandle(std::move(fd), path_ / name);
}

DirectoryHandle DirectoryHandle::make_subdirectory(const std::string& name) const {
  if (::mkdirat(fd_.get(), name.c_str(), 0755) == 0) {
    sync(*this);  // the new directory's entry is durable too
  } else if (errno != EEXIST) {
    throw_file_error("cannot create " + shown(path_ / name), errno);
  }
  std::optional<DirectoryHandle> made = subdirectory(name);
  if (!made) throw InputError("cannot create " + shown(path_ / name) + ": it vanished");
  return std::move(*made);
}

std::optional<FileDescriptor> open_regular_file_at(const DirectoryHandle& directory, const std::string& name, int flags,
                                                   bool single_link) {
  // Refused before it is opened: opening some devices acts (a tape rewinds, a modem hangs up).
  struct stat before {};
  if (::fstatat(directory.fd(), name.c_str(), &before, AT_SYMLINK_NOFOLLOW) == 0 && !S_ISREG(before.st_mode)) {
    throw InputError(name + (S_ISLNK(before.st_mode)
                                 ? " " + open_failure(ELOOP)
                                 : " is " + file_type_name(before.st_mode) + ", not a regular file"));
  }
  // O_NONBLOCK: should a FIFO take its place meanwhile, opening it must not wait for a writer.
  FileDescriptor fd(::openat(directory.fd(), name.c_str(), flags | O_NOFOLLOW | O_NONBLOCK | O_CLOEXEC, 0644));
  if (fd.get() < 0) {
    const int error_number = errno;
    if (error_number == ENOENT && (flags & O_CREAT) == 0) return std::nullopt;
    if (is_environment_failure(error_number)) throw_file_error("cannot open " + name, error_number);
    throw InputError(name + " " + open_failure(error_number));
  }
  struct stat info {};
  if (::fstat(fd.get(), &info) != 0) throw_file_error(name, errno);
  if (!S_ISREG(info.st_mode)) throw InputError(name + " is " + file_type_name(info.st_mode) + ", not a regular file");
  if (single_link && info.st_nlink > 1) {
    throw InputError(name + " has " + std::to_string(info.st_nlink) +
                     " hard links; it is written in place, so it must be the session's own file");
  }
  return fd;
}

std::optional<std::string> read_regular_file_at(const DirectoryHandle& directory, const std::string& name,
                                                std::size_t max_bytes) {
  std::optional<FileDescriptor> fd = open_regular_file_at(directory, name, O_RDONLY);
  if (!fd) return std::nullopt;
  return read_bounded(fd->get(), max_bytes, name);
}

std::string read_regular_file(const fs::path& path, std::size_t max_bytes, const std::string& what) {
  const std::string where = what + " " + shown(path);
  struct stat before {};
  if (::stat(path.c_str(), &before) == 0 && !S_ISREG(before.st_mode)) {  // before opening, as above
    throw InputError(where + " is " + file_type_name(before.st_mode) + ", not a regular file");
  }
  FileDescriptor fd(::open(path.c_str(), O_RDONLY | O_NONBLOCK | O_CLOEXEC));
  if (fd.get() < 0) throw_file_error(where + ": cannot be read", errno);
  return read_bounded(fd.get(), max_bytes, where);
}

int write_all(int fd, std::string_view contents) {
  const char* data = contents.data();
  std::size_t left = contents.size();
  while (left > 0) {
    const ssize_t written = ::write(fd, data, left);
    if (written < 0) {
      if (errno == EINTR) continue;
      return errno;
    }
    data += written;
    left -= static_cast<std::size_t>(written);
  }
  return 0;
}

std::string unpredictable_temporary_name(const std::string& name) {
  // Hidden, marked as a temporary (is_temporary_file_name), and not guessable: a name planted in
  // advance (a link to a victim) is never the one used, and O_EXCL refuses it if it were.
  std::uint64_t random = 0;
  if (::getrandom(&random, sizeof random, 0) != static_cast<ssize_t>(sizeof random)) {
    random =
        static_cast<std::uint64_t>(std::chrono::steady_clock::now().time_since_epoch().count()) * 0x9e3779b97f4a7c15ULL;
  }
  char suffix[40];
  std::snprintf(suffix, sizeof suffix, "%ld-%016llx", static_cast<long>(::getpid()),
                static_cast<unsigned long long>(random));
  std::string temporary = ".";  // built by appends: GCC 12 warns falsely (-Wrestrict) on "." + string
  temporary.append(name.substr(0, 200)).append(".tmp-").append(suffix);
  return temporary;
}

int rename_no_replace(const DirectoryHandle& from_directory, const std::string& from,
                      const DirectoryHandle& to_directory, const std::string& to) {
  if (::renameat2(from_directory.fd(), from.c_str(), to_directory.fd(), to.c_str(), RENAME_NOREPLACE) == 0) return 0;
  if (errno != EINVAL && errno != ENOSYS) return errno;
  // A file system without RENAME_NOREPLACE: a hard link never replaces (files only).
  if (::linkat(from_directory.fd(), from.c_str(), to_directory.fd(), to.c_str(), 0) == 0) {
    ::unlinkat(from_directory.fd(), from.c_str(), 0);
    return 0;
  }
  return errno;
}

void publish_file_at(const DirectoryHandle& from_directory, const std::string& from, const DirectoryHandle& directory,
                     const std::string& name, Replace replace) {
  const int error_number =
      replace == Replace::kAllowed
          ? (::renameat(from_directory.fd(), from.c_str(), directory.fd(), name.c_str()) == 0 ? 0 : errno)
          : rename_no_replace(from_directory, from, directory, name);
  if (error_number == 0) return;
  ::unlinkat(from_directory.fd(), from.c_str(), 0);
  if (error_number == EEXIST)
    throw InputError(shown(directory.path() / name) + " exists already (--force replaces it)");
  throw_file_error("cannot rename a file to " + shown(directory.path() / name), error_number);
}

TemporaryFile::TemporaryFile(const DirectoryHandle& directory, const std::string& name)
    : directory_(directory), name_(name), temporary_(unpredictable_temporary_name(name)) {
  // O_EXCL | O_NOFOLLOW: created here and now, never opened through whatever a name might already be.
  fd_ = FileDescriptor(
      ::openat(directory.fd(), temporary_.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_NOFOLLOW | O_CLOEXEC, 0644));
  if (fd_.get() < 0) {
    const int error_number = errno;
    throw_file_error("cannot create " + shown(directory.path() / name_), error_number);  // the file asked for
  }
}

TemporaryFile::~TemporaryFile() {
  if (!published_) ::unlinkat(directory_.fd(), temporary_.c_str(), 0);
}

void TemporaryFile::fail(const std::string& what, int error_number) {
  ::unlinkat(directory_.fd(), temporary_.c_str(), 0);
  published_ = true;  // nothing left to remove
  throw_file_error("cannot " + what + " " + shown(directory_.path() / name_), error_number);
}

void TemporaryFile::publish(Replace replace, DirectorySync directory_sync) {
  if (::fsync(fd_.get()) != 0) fail("flush", errno);
  if (::close(fd_.release()) != 0) fail("close", errno);
  published_ = true;  // publish_file_at removes it if the rename fails
  publish_file_at(directory_, temporary_, directory_, name_, replace);  // a link at `name` is replaced, never followed
  if (directory_sync == DirectorySync::kNow) sync(directory_);
}

void write_file_atomic_at(const DirectoryHandle& directory, const std::string& name, std::string_view contents,
                          DirectorySync directory_sync, Replace replace) {
  TemporaryFile file(directory, name);
  if (const int error_number = write_all(file.fd(), contents); error_number != 0) file.fail("write", error_number);
  file.publish(replace, directory_sync);
}

void sync(const DirectoryHandle& directory) {
  if (::fsync(directory.fd()) != 0) {
    throw_file_error("cannot flush directory " + shown(directory.path()), errno);
  }
}

bool remove_file_at(const DirectoryHandle& directory, const std::string& name) {
  if (::unlinkat(directory.fd(), name.c_str(), 0) == 0) return true;
  if (errno == ENOENT) return false;
  throw_file_error("cannot remove " + shown(directory.path() / name), errno);
}

std::vector<std::string> entry_names(const DirectoryHandle& directory) {
  std::vector<std::string> names;
  // fdopendir takes over its descriptor: give it a duplicate.
  const int duplicate = ::fcntl(directory.fd(), F_DUPFD_CLOEXEC, 0);
  if (duplicate < 0) return names;
  DIR* stream = ::fdopendir(duplicate);
  if (stream == nullptr) {
    ::close(duplicate);
    return names;
  }
  ::rewinddir(stream);  // the duplicate shares the position of earlier scans
  while (const dirent* entry = ::readdir(stream)) {
    const std::string name = entry->d_name;
    if (name != "." && name != "..") names.push_back(name);
  }
  ::closedir(stream);
  return names;
}

void remove_temporary_files(const DirectoryHandle& directory) {
  for (const std::string& name : entry_names(directory)) {
    if (is_temporary_file_name(name)) ::unlinkat(directory.fd(), name.c_str(), 0);
  }
}

}  // namespace bellows
