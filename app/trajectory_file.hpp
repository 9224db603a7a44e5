// Trajectories in CSV files, uniformly sampled at the ILC sample time: one joint as
// `time_s,angle_deg` (as always), or one column per joint as `time_s,q1_deg,q2_deg[,q3_deg[,q4_deg]]`
// (../shared/spec/multi-joint.md section 3); and the lookup that accepts a library name or a path.
// A UTF-8 byte order mark and CR LF line ends are accepted; text quoted from the file in an error is
// escaped and shortened.
#pragma once

#include <filesystem>
#include <string>

#include "engine/base/parameters.hpp"
#include "engine/trial/trajectory.hpp"
#include "sessions/file_access.hpp"

namespace bellows {

/// Parses CSV text; throws InputError naming `source_name` and the line at fault.
Trajectory parse_trajectory_csv(const std::string& text, const std::string& source_name, double sample_time_s,
                                const TrajectoryLimits& limits);
/// Reads a regular file of at most 64 MiB (a FIFO, device or directory is refused, never waited on).
Trajectory load_trajectory_file(const std::string& path, double sample_time_s, const TrajectoryLimits& limits);
/// A library name ("paper") or a path to a CSV file (anything with '/' or ending in ".csv").
Trajectory resolve_trajectory(const std::string& name_or_path, double sample_time_s, const TrajectoryLimits& limits);

/// The trajectory must have the arm's joints: one without an [arm] preset, else the preset's. Refused
/// with one line ("trajectory 'paper2' has 2 joints; the arm has 1 ([arm] preset)") rather than one
/// of its columns used in silence, or a joint left without set points. Throws InputError.
void require_driven_joints(const Trajectory& trajectory, const ArmParameters& arm);

/// The CSV text parse_trajectory_csv reads back: `time_s,angle_deg` for one joint, else
/// `time_s,q1_deg,...`; angles in the shortest form that reads back to the same degrees.
std::string trajectory_csv(const Trajectory& trajectory);
/// Writes trajectory_csv() to `path` atomically (a temporary file renamed over it).
/// By the safe writer (sessions/file_access.hpp); Replace::kRefused: an existing file is refused
/// ("exists already (--force replaces it)").
void write_trajectory_file(const std::filesystem::path& path, const Trajectory& trajectory,
                           Replace replace = Replace::kAllowed);

}  // namespace bellows
