// Trajectories from CSV files with the header `time_s,angle_deg`, uniformly sampled at the ILC
// sample time, and the lookup that accepts a library name or a path. A UTF-8 byte order mark and
// CR LF line ends are accepted; text quoted from the file in an error is escaped and shortened.
#pragma once

#include <string>

#include "engine/trajectory.hpp"

namespace bellows {

/// Parses CSV text; throws InputError naming `source_name` and the line at fault.
Trajectory parse_trajectory_csv(const std::string& text, const std::string& source_name, double sample_time_s,
                                const TrajectoryLimits& limits);
/// Reads a regular file of at most 64 MiB (a FIFO, device or directory is refused, never waited on).
Trajectory load_trajectory_file(const std::string& path, double sample_time_s, const TrajectoryLimits& limits);
/// A library name ("paper") or a path to a CSV file (anything with '/' or ending in ".csv").
Trajectory resolve_trajectory(const std::string& name_or_path, double sample_time_s, const TrajectoryLimits& limits);

}  // namespace bellows
