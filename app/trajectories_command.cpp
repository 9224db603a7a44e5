#include "app/trajectories_command.hpp"

#include <cstdio>
#include <ostream>

#include "app/config_file.hpp"
#include "app/trajectory_file.hpp"
#include "engine/base/errors.hpp"
#include "engine/trial/trajectory.hpp"

namespace bellows {

int trajectories_command(const TrajectoriesOptions& options, std::ostream& out) {
  const Configuration config = options.config_path.empty() ? Configuration{} : load_config_file(options.config_path);
  const double sample_s = config.timing.sample_s();
  if (options.trajectory.empty()) {
    if (!options.output_path.empty())
      throw InputError("--output needs a trajectory to write (a library name or a file)");
    char row[160];
    std::snprintf(row, sizeof row, "%-8s %6s %9s %8s  %s\n", "name", "joints", "duration", "samples", "description");
    out << row;
    for (const std::string& name : trajectory_library_names()) {
      const Trajectory trajectory = resolve_trajectory(name, sample_s, config.trajectory);
      std::snprintf(row, sizeof row, "%-8s %6d %7.1f s %8d  ", name.c_str(), trajectory.joints(),
                    trajectory.duration_s(), trajectory.learning_samples());
      out << row << trajectory_library_description(name) << "\n";
    }
    return 0;
  }
  const Trajectory trajectory = resolve_trajectory(options.trajectory, sample_s, config.trajectory);
  if (options.output_path.empty()) {
    out << trajectory_csv(trajectory);
  } else {
    write_trajectory_file(options.output_path, trajectory, options.force ? Replace::kAllowed : Replace::kRefused);
  }
  return 0;
}

}  // namespace bellows
