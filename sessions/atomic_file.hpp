// Durable file writes by path (exports, figures, models, trajectories): the same safe writer as the
// session's own files (file_access.hpp, write_file_atomic_at): an exclusive temporary of an
// unpredictable name in the file's own folder, fsync, rename, fsync of the folder, so that a crash
// or power cut at any moment leaves the old file or the new one, never a mix, and a link planted
// anywhere is never written through. Errors throw InputError naming the path and the reason.
#pragma once

#include <cstdio>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <string_view>

#include "sessions/file_access.hpp"

namespace bellows {

/// Writes `path` by the one safe writer (write_file_atomic_at(), file_access.hpp) in its folder:
/// `replace` says whether an existing file may be replaced (the operator's --force).
void write_file_atomic(const std::filesystem::path& path, std::string_view contents,
                       DirectorySync directory_sync = DirectorySync::kNow, Replace replace = Replace::kAllowed);

/// A file written as it goes (the LCM event log of a run) by the one safe writer: the
/// TemporaryFile of `path` in its folder is created at once, written through stream() (a stdio
/// stream whose every flush is this process's own write(2) on the temporary, so the fault shim of
/// the tests sees it), and appears under `path` only at commit(): flush, fsync, rename (refused if
/// `path` exists and `replace` is kRefused), fsync of the folder. Not committed (an error, an
/// exception): the temporary is removed. Killed before commit(): nothing under `path`; the hidden
/// temporary (is_temporary_file_name) holds the events written so far.
class AtomicOutputFile {
 public:
  AtomicOutputFile(const std::filesystem::path& path, Replace replace);
  ~AtomicOutputFile();
  AtomicOutputFile(const AtomicOutputFile&) = delete;
  AtomicOutputFile& operator=(const AtomicOutputFile&) = delete;
  /// Buffered; errors are kept and reported by commit(). Not thread-safe: one writer at a time.
  std::FILE* stream() { return stream_; }
  /// Throws InputError naming the file and why (the first write error, a full disk at the flush).
  void commit();
  const std::filesystem::path& path() const { return path_; }

 private:
  static ssize_t write_cookie(void* cookie, const char* data, std::size_t size);
  std::filesystem::path path_;
  Replace replace_;
  DirectoryHandle folder_;
  std::optional<TemporaryFile> file_;
  static constexpr std::size_t kStreamBuffer = std::size_t{1} << 18;
  std::unique_ptr<char[]> buffer_;  // the stream's (outlives it)
  std::FILE* stream_ = nullptr;
  int write_error_ = 0;  // the errno of the first failed write
};

/// For a file another library writes by path (libmatio): a folder made for it alone (mode 0700,
/// hidden, unpredictable name) in `folder`, so nothing can be planted where it writes; removed
/// with whatever is left in it. publish_file_at() moves the finished file out.
class PrivateTemporaryDirectory {
 public:
  PrivateTemporaryDirectory(const DirectoryHandle& folder, const std::string& name);
  ~PrivateTemporaryDirectory();
  PrivateTemporaryDirectory(const PrivateTemporaryDirectory&) = delete;
  PrivateTemporaryDirectory& operator=(const PrivateTemporaryDirectory&) = delete;
  const DirectoryHandle& handle() const { return *directory_; }
  std::filesystem::path path() const { return folder_->path() / name_; }

 private:
  const DirectoryHandle* folder_;
  std::string name_;
  std::optional<DirectoryHandle> directory_;
};

/// Flushes a directory's entries (new names, renames) to disk.
void sync_directory(const std::filesystem::path& directory);

/// The whole regular file (at most 1 GiB); throws InputError if it cannot be read.
std::string read_file(const std::filesystem::path& path);

/// True for the names write_file_atomic() uses for its temporary files (left behind by a crash).
bool is_temporary_file_name(const std::string& file_name);

}  // namespace bellows
