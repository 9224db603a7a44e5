// Exports of a loaded session for analysis tools (docs/session-format.md, "Exports"):
// - CSV: every iteration's samples stacked in one file with an `iteration` column (tidy data for
//   pandas / readtable), a `_telemetry` file likewise, and a `_summary` file with one row per
//   iteration.
// - MATLAB v7.3 (HDF5) through libmatio: a `session` struct (metadata, configuration, trajectory,
//   per-iteration summary, events) and `iterations`, a 1 x n struct array, one struct per
//   iteration with its `samples` and `telemetry` as structs of column vectors.
// Files are written atomically. Errors throw InputError naming the file.
#pragma once

#include <filesystem>
#include <vector>

#include "sessions/session.hpp"

namespace bellows {

/// Writes the three CSV files; returns their paths (samples, telemetry, summary).
std::vector<std::filesystem::path> export_session_csv(const Session& session, const std::filesystem::path& samples_path);

/// Writes the MAT file; returns its path.
std::filesystem::path export_session_mat(const Session& session, const std::filesystem::path& path);

}  // namespace bellows
