// `bellows trajectories`: the library as a table (name, joints, duration, samples, description) at
// the configuration's sample time; with a name or a CSV file, that trajectory as CSV
// (`time_s,angle_deg` or `time_s,q1_deg,...`, app/trajectory_file) on stdout or into --output,
// checked as `run` checks it: a starting point to edit, or a check of a file before a run.
#pragma once

#include <iosfwd>
#include <string>

namespace bellows {

struct TrajectoriesOptions {
  std::string trajectory;   // empty: list the library
  std::string config_path;  // [timing] (sample time) and [trajectory] (limits)
  std::string output_path;  // empty: stdout
  bool force = false;       // --force: replace an existing --output file
};

int trajectories_command(const TrajectoriesOptions& options, std::ostream& out);

}  // namespace bellows
