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
  throw_file_error("cannot " + what + " " + path.string(), error_number);
}

DirectoryHandle folder_of(const std::filesystem::path& path) {
  const std::filesystem::path directory = path.parent_path().empty() ? "." : path.parent_path();
  const std::string name = path.filename().string();
  if (name.empty() || name == "." || name == "..")
    throw InputError("cannot write " + path.string() + ": not a file name");
  try {
    return DirectoryHandle::open(directory);
  } catch (const InputError& error) {
    throw InputError("cannot create " + path.string() + ": " + error.what());
  }
}

}  // namespace

void write_file_atomic(const std::filesystem::path& path, std::string_view contents, DirectorySync directory_sync,
                       Replace replace) {
  // The folder is the operator's choice (a link in its path is followed); the file itself is
  // written by the one safe writer, inside that folder's descriptor.
  write_file_atomic_at(folder_of(path), path.filename().string(), contents, directory_sync, replace);
}

AtomicOutputFile::AtomicOutputFile(const std::filesystem::path& path, Replace replace)
    : path_(path), replace_(replace), folder_(folder_of(path)), buffer_(std::make_unique<char[]>(kStreamBuffer)) {
  file_.emplace(folder_, path.filename().string());
  const cookie_io_functions_t functions{nullptr, &AtomicOutputFile::write_cookie, nullptr, nullptr};
  stream_ = ::fopencookie(this, "w", functions);
  if (stream_ == nullptr) throw_file_error("cannot open a stream on " + path.string(), errno);
  std::setvbuf(stream_, buffer_.get(), _IOFBF,
               kStreamBuffer);  // few, large writes (glibc ignores a size without a buffer)
}

AtomicOutputFile::~AtomicOutputFile() {
  if (stream_ != nullptr) std::fclose(stream_);  // not committed: whatever it flushes is removed with the temporary
}

ssize_t AtomicOutputFile::write_cookie(void* cookie, const char* data, std::size_t size) {
  auto* self = static_cast<AtomicOutputFile*>(cookie);
  if (self->write_error_ == 0) self->write_error_ = write_all(self->file_->fd(), std::string_view(data, size));
  if (self->write_error_ != 0) {
    errno = self->write_error_;
    return -1;
  }
  return static_cast<ssize_t>(size);
}

void AtomicOutputFile::commit() {
  const int flushed = std::fflush(stream_);
  std::fclose(stream_);
  stream_ = nullptr;
  if (write_error_ != 0 || flushed != 0) file_->fail("write", write_error_ != 0 ? write_error_ : EIO);
  file_->publish(replace_);
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
