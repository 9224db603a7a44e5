// The write side shared by save_session() and SessionWriter: creating a session directory
// atomically (built under a hidden temporary name, then renamed into place) and writing one
// iteration's files. Within sessions/ only.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include "sessions/session.hpp"
#include "sessions/session_lock.hpp"

namespace bellows {

/// Creates `directory` holding the manifest, the trajectory and `iterations` (as listed by the
/// manifest), locked for the caller. Throws InputError if it exists already, naming the process
/// that uses it, if any.
SessionLock create_session_directory(const std::filesystem::path& directory, const SessionManifest& manifest,
                                     const Trajectory& trajectory, const std::vector<IterationData>& iterations,
                                     const std::string& purpose,
                                     const std::vector<std::vector<TickRecord>>& black_boxes = {});

/// Writes iteration `index`'s samples and telemetry files (durable once the caller syncs the
/// iterations directory). Throws InputError for a value that is not finite.
void write_iteration_files(const std::filesystem::path& directory, int index, const TrialRecord& record,
                           const Eigen::VectorXd& next_correction_bar);

/// Writes black box `index` into the faults directory (created if needed) and syncs it.
void write_black_box_file(const std::filesystem::path& directory, int index, const std::vector<TickRecord>& ticks);

/// Writes the manifest, stamping `updated_utc`.
void write_manifest(const std::filesystem::path& directory, SessionManifest& manifest);

}  // namespace bellows
