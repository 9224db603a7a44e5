#include "sessions/atomic_file.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <utility>

#include "engine/base/errors.hpp"

namespace bellows {
namespace {

constexpr std::string_view kTemporaryMarker = ".tmp-";

[[noreturn]] void fail(const std::string& what, const std::filesystem::path& path, int error_number) {
  throw InputError("cannot " + what + " " + path.string() + ": " + std::strerror(error_number));
}

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
  if (const int error_number = write_all(fd.get(), contents); error_number != 0) {
    ::unlink(temporary.c_str());
    fail("write", temporary, error_number);
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
  constexpr std::size_t kLargest = std::size_t{1} << 30;
  return read_regular_file(path, kLargest, "file");
}

bool is_temporary_file_name(const std::string& file_name) {
  return !file_name.empty() && file_name.front() == '.' && file_name.find(kTemporaryMarker) != std::string::npos;
}

}  // namespace bellows
