// Durable file writes by path (exports; a session's own files go through file_access.hpp): a file
// is written under a temporary name in its own directory, flushed to disk (fsync), renamed over its
// final name, and the directory is flushed, so that a crash or power cut at any moment leaves
// either the old file or the new one, never a mix. Errors throw InputError naming the path and the
// system's reason.
#pragma once

#include <filesystem>
#include <string>
#include <string_view>

#include "sessions/file_access.hpp"

namespace bellows {

/// Replaces `path` by `contents` atomically and durably.
void write_file_atomic(const std::filesystem::path& path, std::string_view contents,
                       DirectorySync directory_sync = DirectorySync::kNow);

/// The hidden temporary name write_file_atomic() uses for `path` in this process.
std::filesystem::path temporary_path_for(const std::filesystem::path& path);

/// Flushes a directory's entries (new names, renames) to disk.
void sync_directory(const std::filesystem::path& directory);

/// The whole regular file (at most 1 GiB); throws InputError if it cannot be read.
std::string read_file(const std::filesystem::path& path);

/// True for the names write_file_atomic() uses for its temporary files (left behind by a crash).
bool is_temporary_file_name(const std::string& file_name);

}  // namespace bellows
