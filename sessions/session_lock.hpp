// One writer per session: an exclusive advisory lock (flock) on the session's `lock` file, held
// for the writer's lifetime. The kernel releases it when the process ends, even by kill -9, so a
// crashed writer never blocks a resume. The file names its holder, for the refusal message.
// The lock file is opened inside the session's directory without following a link, and must be a
// regular file of its own (one hard link): it is the one file written in place.
#pragma once

#include <filesystem>
#include <optional>
#include <string>

#include "sessions/file_access.hpp"

namespace bellows {

class SessionLock {
 public:
  /// Takes the lock of the session in `directory`; throws InputError naming the current holder
  /// when another process has it. `purpose` (e.g. "bellows run") goes into the holder's line.
  SessionLock(const DirectoryHandle& directory, const std::string& purpose);
  SessionLock(const std::filesystem::path& directory, const std::string& purpose)
      : SessionLock(DirectoryHandle::open(directory), purpose) {}
  ~SessionLock();
  SessionLock(SessionLock&& other) noexcept;
  SessionLock& operator=(SessionLock&& other) noexcept;
  SessionLock(const SessionLock&) = delete;
  SessionLock& operator=(const SessionLock&) = delete;

  /// The holder's line when another process holds the lock of the session in `directory`.
  /// Creates nothing: a directory without a lock file has no holder.
  static std::optional<std::string> holder(const DirectoryHandle& directory);
  static std::optional<std::string> holder(const std::filesystem::path& directory);

  static constexpr const char* kFileName = "lock";

 private:
  int fd_ = -1;
};

}  // namespace bellows
