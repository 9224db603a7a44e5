// Sessions on disk: where they live, how they are named, loading them (checked completely) and
// writing a whole session at once. Incremental writing during a run is SessionWriter's job.
#pragma once

#include <ctime>
#include <filesystem>
#include <string>
#include <vector>

#include "sessions/file_access.hpp"
#include "sessions/session.hpp"

namespace bellows {

/// $XDG_DATA_HOME/bellows/sessions, else ~/.local/share/bellows/sessions. InputError if neither
/// variable gives an absolute path.
std::filesystem::path default_data_dir();

/// The data directory an operator named (--data-dir), which must exist: a typo is refused with
/// InputError rather than answered "no sessions". Empty: default_data_dir(), which may not exist yet.
std::filesystem::path given_data_dir(const std::string& option_value);

/// "2024-05-01_14-03-07_paper": the local start time, then the trajectory's name (made safe).
std::string default_session_name(std::time_t start, const std::string& trajectory_name);
/// Throws InputError unless `name` is a plain directory name (no '/', not hidden, printable).
void validate_session_name(const std::string& name);
/// Why a session in `parent` cannot take `name` (validate_session_name's rule, or an entry of that
/// name exists already), or "" when it can: for a prompt that checks a name before it closes.
std::string session_name_refusal(const std::string& name, const std::filesystem::path& parent);
/// Renames the session in `directory` to `new_name` beside it, under the session's lock: the
/// directory and its manifest's name (which `sessions show` and `sessions list` print). Returns the
/// new directory. Throws InputError (a bad or taken name, the session locked or unreadable). The
/// one rename of `bellows sessions rename` and the console's `s`.
std::filesystem::path rename_session(const std::filesystem::path& directory, const std::string& new_name);

/// A session given as a directory path, or as the name of one inside `data_dir`.
std::filesystem::path resolve_session_dir(const std::string& path_or_name, const std::filesystem::path& data_dir);

/// Opens a session's directory; InputError "session DIR: no such directory" and the like.
DirectoryHandle open_session_directory(const std::filesystem::path& directory);

/// The manifest alone (fast, for listings). Throws InputError for anything missing or malformed.
SessionManifest load_manifest(const std::filesystem::path& directory);
SessionManifest load_manifest(const DirectoryHandle& directory);
/// Everything: manifest, trajectory, every listed iteration's samples and telemetry, each checked
/// (lengths, sampling, finite values, RMS against the manifest, the file's SHA-256 digest against
/// the manifest's). Every file is opened inside the session without following a link; a link,
/// a special file or a file larger than its format allows is refused. Throws InputError.
Session load_session(const std::filesystem::path& directory);
Session load_session(const DirectoryHandle& directory);
/// Like load_session, but reads (and checks) only the files of the iterations `only` lists (by
/// index; an index the manifest does not list is ignored) and no black box: every other iteration
/// keeps an empty record (learning_samples 0). What needs a few iterations of a long session
/// (figures) reads those alone.
Session load_session_iterations(const std::filesystem::path& directory, const std::vector<int>& only);

/// The one line that says what an interrupted save dropped (Session::dropped), "" when nothing:
/// "session S: a save was interrupted; dropped what it had not committed: iteration 5; this is its
/// last committed state (5 iterations)".
std::string dropped_line(const Session& session);

/// Writes `session` as a new directory `directory` (which must not exist yet), atomically: the
/// directory appears complete or not at all.
void save_session(const Session& session, const std::filesystem::path& directory);

struct SessionListing {
  std::filesystem::path directory;
  SessionManifest manifest;  // valid when `error` is empty
  std::string error;
};
/// Every session directory in `data_dir` (hidden entries and plain files skipped), oldest first.
/// A session that cannot be read (a link, a bad manifest, anything) is listed with its error and
/// never hides the others. A missing data directory has no sessions.
std::vector<SessionListing> list_sessions(const std::filesystem::path& data_dir);

/// The lowest RMS of the listed iterations, or a negative value if there are none.
double best_rms_deg(const SessionManifest& manifest);

}  // namespace bellows
