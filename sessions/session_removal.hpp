// Removing a session (`bellows sessions rm`): only what the session layout names is removed, each
// entry unlinked inside the session's own directory (a link is removed itself, never followed),
// and a folder that holds anything else is refused before anything is removed.
#pragma once

#include <string>
#include <vector>

#include "sessions/file_access.hpp"

namespace bellows {

/// The entries of `session` (and of its iterations/ and faults/ folders) that the session layout
/// does not name, as "notes.txt", "iterations/x.csv": a folder with any is not removed.
/// Folders of the layout that are links or not directories are listed too.
std::vector<std::string> foreign_session_entries(const DirectoryHandle& session);

/// Unlinks every entry the layout names, then the iterations/ and faults/ folders. Throws
/// InputError naming the entry that could not be removed.
void remove_session_entries(const DirectoryHandle& session);

}  // namespace bellows
