// `bellows run`: trials on the simulated arm, learning between them, headless.
#pragma once

#include <cstdint>
#include <iosfwd>
#include <string>

#include "engine/configuration.hpp"

namespace bellows {

struct RunOptions {
  std::string trajectory = "paper";
  int iterations = 30;  // learning iterations after the feedback-only trial
  std::string config_path;
  std::uint64_t seed = 1;
  bool json = false;
  // Sessions: saved as the run goes into data_dir/session_name unless no_save.
  bool no_save = false;
  std::string data_dir;      // empty: $XDG_DATA_HOME/bellows/sessions or ~/.local/share/bellows/sessions
  std::string session_name;  // empty: start time and trajectory
  std::string resume_dir;    // continue this session (its configuration, trajectory and state)
};

/// Runs and reports. Progress lines go to `progress`; with --json one object goes to `out`.
/// Throws InputError for bad input (before any trial runs).
int run_command(const RunOptions& options, std::ostream& out, std::ostream& progress);

}  // namespace bellows
