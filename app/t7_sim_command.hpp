// `bellows t7-sim`: the simulated arm behind a simulated LabJack T7 on Modbus TCP (127.0.0.1:5020 by
// default), as the mock rig of tests and the demo without hardware (docs/labjack-t7.md).
// Runs until SIGINT/SIGTERM (or --duration).
#pragma once

#include <cstdint>
#include <iosfwd>
#include <string>

namespace bellows {

struct T7SimCommandOptions {
  std::string listen = "127.0.0.1:5020";  // HOST[:PORT]
  std::string config_path;                // [plant]
  std::string rig_profile;                // "": the paper rig's
  std::uint64_t seed = 1;
  double duration_s = 0.0;  // 0: until a signal
  std::string status_path;  // the status file ("": none)
  // Drills.
  bool swapped_chambers = false;
  std::string dead_valve;  // inlet_a, inlet_b, outlet_a, outlet_b
  bool no_supply = false;
  double silent_after_s = -1.0;
  double stall_after_s = -1.0;
  double stall_s = 0.05;
  std::string product = "t7-pro";  // t7 | t7-pro
  bool nagle = false;
  double answer_after_s = 0.0;
  double trickle_after_s = -1.0;
  double trickle_byte_s = 0.4;
  bool silent_reads = false;
  bool streaming = false;
  double halve_roll_after_s = -1.0;
};

int t7_sim_command(const T7SimCommandOptions& options, std::ostream& out);

}  // namespace bellows
