// Exports of a loaded session for analysis tools (docs/session-format.md, "Exports"):
// - CSV: every iteration's samples stacked in one file with an `iteration` column (tidy data for
//   pandas / readtable), a `_telemetry` file likewise, a `_summary` file with one row per
//   iteration, and, when the session has faults, a `_blackbox` file with every black box stacked
//   under a `black_box` column.
// - MATLAB through libmatio: MAT v5 (zlib-compressed) by default, which scipy's loadmat, Octave
//   and MATLAB all read; v7.3 (HDF5) on request for sessions beyond v5's 2 GB per variable.
//   Variables: `session` (metadata, configuration, trajectory, per-iteration summary, events),
//   `iterations` (1 x n struct array: `samples` and `telemetry` as structs of column vectors) and
//   `black_boxes` (1 x faults struct array; state and fault as cell arrays of names).
// An export never replaces an existing file unless forced, never writes into the session it
// exports, and needs the extension of its format. Files are written atomically. Errors throw
// InputError naming the file.
#pragma once

#include <filesystem>
#include <vector>

#include "sessions/session.hpp"

namespace bellows {

enum class MatVersion { kV5, kV73 };

/// Every file export_session_csv() writes for `samples_path`: samples, telemetry, summary and
/// (only when the session has black boxes) black boxes.
std::vector<std::filesystem::path> csv_export_paths(const Session& session, const std::filesystem::path& samples_path);

/// Writes the CSV files; returns their paths (as csv_export_paths()).
std::vector<std::filesystem::path> export_session_csv(const Session& session, const std::filesystem::path& samples_path,
                                                      bool force = false);

/// Writes the MAT file; returns its path.
std::filesystem::path export_session_mat(const Session& session, const std::filesystem::path& path,
                                         MatVersion version = MatVersion::kV5, bool force = false);

/// Throws InputError unless every path in `paths` may be written: `extension` (".csv") on the
/// first, an existing folder, not inside the session's directory, and no existing file unless
/// `force`. Nothing is written by an export that any of these refuses.
void check_export_targets(const Session& session, const std::vector<std::filesystem::path>& paths,
                          const std::string& extension, bool force);

}  // namespace bellows
