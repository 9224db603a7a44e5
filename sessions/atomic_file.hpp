// Durable file writes by path (exports, figures, models, trajectories): the same safe writer as the
// session's own files (file_access.hpp, write_file_atomic_at): an exclusive temporary of an
// unpredictable name in the file's own folder, fsync, rename, fsync of the folder, so that a crash
// or power cut at any moment leaves the old file or the new one, never a mix, and a link planted
// anywhere is never written through. Errors throw InputError naming the path and the reason.
#pragma once

#include <filesystem>
#include <optional>
#include <string>
#include <string_view>

#include "sessions/file_access.hpp"

namespace bellows {

/// Writes `path` by the one safe writer (write_file_atomic_at(), file_access.hpp) in its folder:
/// `replace` says whether an existing file may be replaced (the operator's --force).
void write_file_atomic(const std::filesystem::path& path, std::string_view contents,
                       DirectorySync directory_sync = DirectorySync::kNow, Replace replace = Replace::kAllowed);

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
