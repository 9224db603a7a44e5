// `--device t7` in one function: the address and the rig profile on the command line (or in the
// [device] section) become a connected, configured T7Device. The device factory calls it.
#pragma once

#include <memory>
#include <string>

#include "engine/config/configuration.hpp"
#include "devices/t7_device.hpp"

namespace bellows {

inline constexpr int kDefaultT7Port = 502;      // Modbus TCP
inline constexpr int kDefaultT7SimPort = 5020;  // `bellows t7-sim` (unprivileged)

struct T7Options {
  std::string address;      // --t7 HOST[:PORT]
  std::string rig_profile;  // --rig-profile FILE; "": the paper rig's, built in
  bool realtime = true;     // ask for SCHED_FIFO for the Modbus I/O thread
};

/// Splits "HOST[:PORT]" ("[v6]:PORT" too). Throws InputError naming the address when it is malformed.
/// `option` names it in the error; `lowest_port` 0 lets a server ask for any free port.
void parse_host_port(const std::string& address, int default_port, std::string& host, int& port,
                     const std::string& option = "--t7", int lowest_port = 1);

/// Loads the profile and connects. Throws InputError for a bad address or profile (exit 2) and
/// EnvironmentError for an address that cannot be reached or is no T7 (exit 4); nothing is armed.
/// The T7Device is a Device; it also tells its address(), its profile().name, and stop()s.
std::unique_ptr<T7Device> open_t7_device(const T7Options& options, const Configuration& config);

}  // namespace bellows
