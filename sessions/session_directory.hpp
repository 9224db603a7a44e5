// The write side shared by save_session() and SessionWriter: creating a session directory
// atomically (built under a hidden temporary name, then renamed into place) and writing one
// iteration's files. Every file is written relative to the session's directory descriptor, never
// through a symbolic link (file_access.hpp), and its SHA-256 digest goes into the manifest.
// Within sessions/ only.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include "engine/base/errors.hpp"
#include "sessions/file_access.hpp"
#include "sessions/manifest_json.hpp"
#include "sessions/session.hpp"
#include "sessions/session_lock.hpp"

namespace bellows {

/// A session directory just created, locked for its creator.
/// The session directory to create exists already (or another process created it first).
class SessionExistsError : public InputError {
 public:
  using InputError::InputError;
};

struct CreatedSession {
  DirectoryHandle directory;
  SessionLock lock;
  SessionManifest manifest;  // as written: with the digests of the files
};

/// Creates `directory` holding the manifest, the trajectory and `iterations` (as listed by the
/// manifest), locked for the caller. Throws InputError if it exists already, naming the process
/// that uses it, if any.
/// "session <directory>", escaped, for messages about one session.
std::string describe_session(const std::filesystem::path& directory);

CreatedSession create_session_directory(const std::filesystem::path& directory, const SessionManifest& manifest,
                                        const Trajectory& trajectory, const std::vector<IterationData>& iterations,
                                        const std::string& purpose,
                                        const std::vector<std::vector<TickRecord>>& black_boxes = {});

/// The digests of one iteration's two files.
struct IterationDigests {
  std::string samples_sha256, telemetry_sha256;
};

/// Writes iteration `index`'s samples and telemetry files into the session's `iterations` folder
/// (durable once the caller syncs it), every joint of the record (`next_corrections_bar` N x J).
/// Throws InputError for a value that is not finite.
IterationDigests write_iteration_files(const DirectoryHandle& iterations, int index, const TrialRecord& record,
                                       const Eigen::MatrixXd& next_corrections_bar);

/// Writes black box `index` into the session's faults folder (created if needed), synced; returns
/// its digest.
std::string write_black_box_file(const DirectoryHandle& session, int index, const std::vector<TickRecord>& ticks);

/// Writes the manifest, stamping `updated_utc`.
void write_manifest(const DirectoryHandle& session, SessionManifest& manifest, ManifestTextCache* cache = nullptr);

}  // namespace bellows
