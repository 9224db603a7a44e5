// `bellows io-sim`: the simulated arm as its own process, serving the LCM rig protocol in real time
// (docs/lcm-protocol.md), as a rig would. Runs until SIGINT/SIGTERM (or --duration), then vents.
#pragma once

#include <cstdint>
#include <iosfwd>
#include <string>

#include "engine/rt/realtime_loop.hpp"

namespace bellows {

struct IoSimOptions {
  std::string config_path;  // [plant], [arm] preset (the arm of several joints served), [timing] tick_s, [controller]
                            // p_max_bar, [lcm] (timeout, window, limits, key_file)
  std::uint64_t seed = 1;   // of the arm's sensor noise
  std::string lcm_url;      // empty: the default bus
  RealtimeMode rt = RealtimeMode::kTry;
  double duration_s = 0.0;        // 0: until a signal
  bool json = false;              // counters as one JSON object on `out` at exit
  bool swapped_chambers = false;  // drill: the tubes of chambers A and B swapped (devices/swapped_chambers.hpp)
  bool stepped = false;  // lockstep: one period of physics per command, answered at once (run --clock lockstep)
  bool no_command_timeout =
      false;  // drill: the rig announces its [lcm] rig_timeout_s but never vents when commands stop
};

/// Serves until stopped. Progress lines go to `progress`. Throws InputError for bad input or a bus
/// that cannot be opened. Returns the exit status (0 after a signal or the duration).
int io_sim_command(const IoSimOptions& options, std::ostream& out, std::ostream& progress);

}  // namespace bellows
