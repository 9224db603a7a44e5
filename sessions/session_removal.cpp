#include "sessions/session_removal.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <optional>
#include <regex>

#include "engine/base/errors.hpp"
#include "sessions/atomic_file.hpp"
#include "sessions/file_access.hpp"
#include "sessions/session_layout.hpp"
#include "sessions/session_lock.hpp"

namespace bellows {
namespace {

// The layout's names (docs/session-format.md, "Layout"), per folder.
bool top_level_name(const std::string& name) {
  static const std::regex lcm_log("telemetry(-[0-9]+)?\\.lcmlog");
  return name == session_layout::kManifest || name == session_layout::kTrajectory || name == SessionLock::kFileName ||
         is_temporary_file_name(name) || std::regex_match(name, lcm_log);
}
bool iterations_name(const std::string& name) {
  static const std::regex file("(iteration_[0-9]{4,}(\\.r[1-9][0-9]*)?|telemetry_[0-9]{4,})\\.csv");
  return is_temporary_file_name(name) || std::regex_match(name, file);
}
bool faults_name(const std::string& name) {
  static const std::regex file("blackbox_[0-9]{4,}\\.csv");
  return is_temporary_file_name(name) || std::regex_match(name, file);
}

/// The kind of `name` in `directory`, not following a link.
mode_t kind_of(const DirectoryHandle& directory, const std::string& name) {
  struct stat info {};
  if (::fstatat(directory.fd(), name.c_str(), &info, AT_SYMLINK_NOFOLLOW) != 0) return 0;
  return info.st_mode & S_IFMT;
}

}  // namespace

std::vector<std::string> foreign_session_entries(const DirectoryHandle& session) {
  std::vector<std::string> foreign;
  for (const std::string& name : entry_names(session)) {
    const mode_t kind = kind_of(session, name);
    if (name == session_layout::kIterations || name == session_layout::kFaults) {
      if (kind != S_IFDIR) {
        foreign.push_back(name + " (" + file_type_name(kind) + ", not a folder)");
        continue;
      }
      const std::optional<DirectoryHandle> folder = session.subdirectory(name);
      if (!folder) continue;
      const auto known = name == session_layout::kIterations ? iterations_name : faults_name;
      for (const std::string& inner : entry_names(*folder)) {
        if (!known(inner) || kind_of(*folder, inner) == S_IFDIR) foreign.push_back(name + "/" + inner);
      }
    } else if (!top_level_name(name) || kind == S_IFDIR) {
      foreign.push_back(name);
    }
  }
  return foreign;
}

void remove_session_entries(const DirectoryHandle& session) {
  const auto unlink_in = [](const DirectoryHandle& directory, const std::string& name, int flags) {
    if (::unlinkat(directory.fd(), name.c_str(), flags) != 0 && errno != ENOENT) {
      throw_file_error("cannot remove " + (directory.path() / name).string(), errno);
    }
  };
  for (const char* folder_name : {session_layout::kIterations, session_layout::kFaults}) {
    const std::optional<DirectoryHandle> folder = session.subdirectory(folder_name);  // never a link
    if (!folder) continue;
    const auto known = std::string(folder_name) == session_layout::kIterations ? iterations_name : faults_name;
    for (const std::string& name : entry_names(*folder)) {
      if (known(name)) unlink_in(*folder, name, 0);
    }
    unlink_in(session, folder_name, AT_REMOVEDIR);
  }
  for (const std::string& name : entry_names(session)) {
    if (top_level_name(name) && name != session_layout::kManifest) unlink_in(session, name, 0);
  }
  unlink_in(session, session_layout::kManifest, 0);  // last: until then it is still a session
}

}  // namespace bellows
