// Files inside a session, reached only through the session's own directory: every name is opened
// relative to a directory descriptor (openat) without following a symbolic link (O_NOFOLLOW), only
// regular files and real directories are accepted, special files are opened without blocking
// (O_NONBLOCK) and refused, and every read is bounded by the size its format allows. So a session
// cannot make bellows read or write outside it, hang on a FIFO or read /dev/zero for ever.
// Errors name the file and what is wrong with it: InputError (exit status 2) when the name is what is
// wrong, EnvironmentError (4) when the system could not do it (throw_file_error).
#pragma once

#include <cstddef>
#include <filesystem>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace bellows {

/// Whether a file system call that failed with `error_number` failed for want of a working disk or
/// of the system's resources (full, over quota, read-only, an I/O error, no memory or descriptors
/// left), not because of the name it was given (missing, not a folder, a link, no permission).
bool is_environment_failure(int error_number);

/// Throws "`message`: <the system's reason>": EnvironmentError (exit status 4, "a disk that cannot
/// be written", docs/architecture.md) when is_environment_failure(error_number), else InputError (2).
[[noreturn]] void throw_file_error(const std::string& message, int error_number);

/// Whether `path` lies inside `directory`, both resolved (`..`, symbolic links): where an output
/// would land inside a session it was made from.
bool is_inside(const std::filesystem::path& path, const std::filesystem::path& directory);

/// Closes a descriptor on every path out of a scope.
class FileDescriptor {
 public:
  FileDescriptor() = default;
  explicit FileDescriptor(int fd) : fd_(fd) {}
  ~FileDescriptor();
  FileDescriptor(FileDescriptor&& other) noexcept;
  FileDescriptor& operator=(FileDescriptor&& other) noexcept;
  FileDescriptor(const FileDescriptor&) = delete;
  FileDescriptor& operator=(const FileDescriptor&) = delete;
  int get() const { return fd_; }
  int release();

 private:
  int fd_ = -1;
};

/// An open directory: its descriptor and, for messages only, the path it was opened by.
class DirectoryHandle {
 public:
  /// Opens the directory the caller names (a symbolic link the operator gives is followed: it is
  /// the operator's choice). Throws InputError when it is not a directory.
  static DirectoryHandle open(const std::filesystem::path& path);
  /// The subdirectory `name` of this one, which must be a real directory, not a symbolic link.
  /// nullopt when it does not exist.
  std::optional<DirectoryHandle> subdirectory(const std::string& name) const;
  /// As subdirectory(), creating it (and syncing this directory) when it does not exist.
  DirectoryHandle make_subdirectory(const std::string& name) const;

  /// The same directory after it was renamed to `path` (the descriptor follows the directory).
  DirectoryHandle moved_to(const std::filesystem::path& path) && { return DirectoryHandle(std::move(fd_), path); }

  int fd() const { return fd_.get(); }
  const std::filesystem::path& path() const { return path_; }

 private:
  DirectoryHandle(FileDescriptor fd, std::filesystem::path path) : fd_(std::move(fd)), path_(std::move(path)) {}
  FileDescriptor fd_;
  std::filesystem::path path_;
};

/// Opens `name` in `directory` as a regular file without following a symbolic link and without
/// blocking on a FIFO; `flags` are open(2)'s (O_RDONLY, O_RDWR | O_CREAT, ...). Refuses anything
/// but a regular file, and a file with other hard links when `single_link` (it is written in place).
/// nullopt when it does not exist (and O_CREAT is not in `flags`).
std::optional<FileDescriptor> open_regular_file_at(const DirectoryHandle& directory, const std::string& name, int flags,
                                                   bool single_link = false);

/// The whole regular file `name` in `directory`, at most `max_bytes` long; nullopt when it does
/// not exist. Throws InputError ("trajectory.csv is a symbolic link", "is a FIFO", "is larger
/// than ...").
std::optional<std::string> read_regular_file_at(const DirectoryHandle& directory, const std::string& name,
                                                std::size_t max_bytes);

/// A file the operator names (--config, --trajectory): a symbolic link is followed, but anything
/// that is not a regular file is refused without blocking, and more than `max_bytes` is refused.
/// Errors: InputError "<what> <path>: ...".
std::string read_regular_file(const std::filesystem::path& path, std::size_t max_bytes, const std::string& what);

/// What a file type is called in a message: "a directory", "a FIFO", "a character device", ...
std::string file_type_name(unsigned mode);

/// Writes all of `contents` to `fd`, again after an interrupted write(2): 0, or the errno that stopped it.
int write_all(int fd, std::string_view contents);

enum class DirectorySync { kNow, kLater /* the caller calls sync() once for a batch */ };
/// Whether a write may replace a file of the same name (the operator's --force, or a file bellows
/// owns such as a manifest), or must refuse: "<path> exists already (--force replaces it)".
enum class Replace { kAllowed, kRefused };

/// The one safe writer's temporary: `name`'s hidden temporary of an unpredictable name
/// (unpredictable_temporary_name) in `directory`, created now with O_CREAT | O_EXCL | O_NOFOLLOW
/// (so never through a link planted in advance). Write to fd() (write_all, or a stream over it),
/// then publish(): fsync, close, rename over `name` (a link there is replaced, never followed; with
/// Replace::kRefused, renameat2(RENAME_NOREPLACE): an existing name is refused, also one that
/// appeared meanwhile), fsync of the directory. Not published (an error, an exception): removed.
/// `directory` must outlive it.
class TemporaryFile {
 public:
  TemporaryFile(const DirectoryHandle& directory, const std::string& name);
  ~TemporaryFile();
  TemporaryFile(const TemporaryFile&) = delete;
  TemporaryFile& operator=(const TemporaryFile&) = delete;
  int fd() const { return fd_.get(); }
  /// Throws InputError "cannot write <temporary>: <why>" (what the temporary is removed after).
  [[noreturn]] void fail(const std::string& what, int error_number);
  /// Throws InputError naming the file and the reason; the temporary is gone either way.
  void publish(Replace replace, DirectorySync directory_sync = DirectorySync::kNow);

 private:
  const DirectoryHandle& directory_;
  std::string name_;
  std::string temporary_;
  FileDescriptor fd_;
  bool published_ = false;
};

/// The one safe writer of bellows (the session store's files and every output outside it):
/// writes `name` in `directory` atomically and durably. A hidden temporary of an unpredictable
/// name (unpredictable_temporary_name) is created with O_CREAT | O_EXCL | O_NOFOLLOW (so never
/// through a link planted in advance), written, flushed (fsync), renamed over `name` (which
/// replaces a link, never follows it; with Replace::kRefused, renameat2(RENAME_NOREPLACE): an
/// existing name is refused, also one that appeared meanwhile), and the directory is flushed.
/// A crash at any moment leaves the old file or the new one, never a mix.
/// (A TemporaryFile written whole and published.)
void write_file_atomic_at(const DirectoryHandle& directory, const std::string& name, std::string_view contents,
                          DirectorySync directory_sync = DirectorySync::kNow, Replace replace = Replace::kAllowed);

/// ".<name>.tmp-<pid>-<64 random bits>": a temporary's name for `name`.
std::string unpredictable_temporary_name(const std::string& name);

/// Renames `from` (in `from_directory`) to `name` in `directory` as write_file_atomic_at()
/// publishes its temporary; on failure `from` is removed and InputError thrown.
void publish_file_at(const DirectoryHandle& from_directory, const std::string& from, const DirectoryHandle& directory,
                     const std::string& name, Replace replace);

/// renameat2(RENAME_NOREPLACE), or a hard link where the file system lacks it: 0 or the errno.
int rename_no_replace(const DirectoryHandle& from_directory, const std::string& from,
                      const DirectoryHandle& to_directory, const std::string& to);

/// Flushes a directory's entries (new names, renames) to disk.
void sync(const DirectoryHandle& directory);

/// Removes `name` from `directory` (a link itself, never what it points to). False if absent.
bool remove_file_at(const DirectoryHandle& directory, const std::string& name);

/// The names in `directory` (not "." and ".."), in no particular order; empty if it cannot be read.
std::vector<std::string> entry_names(const DirectoryHandle& directory);

/// Removes temporary files a crashed writer left in `directory` (not recursive).
void remove_temporary_files(const DirectoryHandle& directory);

}  // namespace bellows
