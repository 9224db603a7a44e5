// What an interrupted save left in a session: files it wrote that the manifest (the commit point of
// every save) does not name. A save writes new content under new names only (the next iteration's
// files, a new revision of the last iteration's samples file, the next black box, a hidden
// temporary) and commits by renaming the manifest over the old one; so whatever the manifest does
// not name was never committed. The loader says what it dropped; the writer removes it.
#pragma once

#include <string>
#include <vector>

#include "sessions/file_access.hpp"
#include "sessions/session.hpp"

namespace bellows {

struct UncommittedFile {
  std::string folder;       // "" (the session's top), "iterations" or "faults"
  std::string name;         // in that folder
  std::string description;  // what was dropped ("iteration 5", ...); empty: superseded, nothing lost
};

/// The session layout's files in `session` that `manifest` does not name (a file of a name the
/// layout does not use is not bellows's and is left alone). Folders that are links are skipped.
std::vector<UncommittedFile> find_uncommitted_files(const DirectoryHandle& session, const SessionManifest& manifest);

/// The line Session::dropped holds: what `files` dropped, each thing once ("" when nothing was lost).
std::string describe_dropped(const std::vector<UncommittedFile>& files);

/// The hidden temporaries of LCM logs (`run --lcm-log` into the session) that a kill cut short: not a
/// save's leftovers but a record of what the run sent, readable up to its last whole event. Each is
/// renamed to its log's name, or telemetry-N.lcmlog when that is taken (the session's directory
/// synced); returns the names it now has. find_uncommitted_files() does not list them.
std::vector<std::string> keep_interrupted_logs(const DirectoryHandle& session);

/// Removes `files` from `session` (links themselves, never what they point to).
void remove_uncommitted_files(const DirectoryHandle& session, const std::vector<UncommittedFile>& files);

}  // namespace bellows
