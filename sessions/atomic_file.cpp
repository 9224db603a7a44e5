#include "sessions/atomic_file.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <optional>
#include <utility>

#include "engine/base/errors.hpp"

namespace bellows {
namespace {

constexpr std::string_view kTemporaryMarker = ".tmp-";  // unpredictable_temporary_name()'s

[[noreturn]] void fail(const std::string& what, const std::filesystem::path& path, int error_number) {
  throw InputError("cannot " + what + " " + path.string() + ": " + std::strerror(error_number));
}

}  // namespace

void write_file_atomic(const std::filesystem::path& path, std::string_view contents, DirectorySync directory_sync,
                       Replace replace) {
  // The folder is the operator's choice (a link in its path is followed); the file itself is
  // written by the one safe writer, inside that folder's descriptor.
  const std::filesystem::path directory = path.parent_path().empty() ? "." : path.parent_path();
  const std::string name = path.filename().string();
  if (name.empty() || name == "." || name == "..") throw InputError("cannot write " + path.string() + ": not a file name");
  write_file_atomic_at(DirectoryHandle::open(directory), name, contents, directory_sync, replace);
}

PrivateTemporaryDirectory::PrivateTemporaryDirectory(const DirectoryHandle& folder, const std::string& name)
    : folder_(&folder), name_(unpredictable_temporary_name(name)) {
  // 0700 and made here (mkdirat fails on any existing name): nobody else can plant a link in it.
  if (::mkdirat(folder.fd(), name_.c_str(), 0700) != 0) fail("create", folder.path() / name_, errno);
  std::optional<DirectoryHandle> made = folder.subdirectory(name_);
  if (!made) fail("open", folder.path() / name_, ENOENT);
  directory_.emplace(std::move(*made));
}

PrivateTemporaryDirectory::~PrivateTemporaryDirectory() {
  if (directory_) {
    for (const std::string& entry : entry_names(*directory_)) ::unlinkat(directory_->fd(), entry.c_str(), 0);
  }
  ::unlinkat(folder_->fd(), name_.c_str(), AT_REMOVEDIR);
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
