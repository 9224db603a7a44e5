// `bellows t7-sim`: a Modbus TCP server that behaves as the subset of a LabJack T7 bellows uses
// (devices/t7_sim_registers.hpp), with the simulated arm behind it in real time. The arm's sensor
// values (noise included) become input voltages through the inverse of the rig profile's
// calibration; the duty cycles the PWM lines output drive the arm's valves. Drills make it
// misbehave: swapped chamber wiring, a dead valve, no supply, a silent link. Like io-sim, it is a
// rig that enforces its own limits whatever it is sent (devices/lcm_rig_limits.hpp): a chamber at
// the pressure ceiling is vented, and an arm beyond the angle range vents everything until the
// client writes its duties again.
//
// As strict as a T7 (devices/t7_sim_rules.hpp): what LabJack documents a T7 refuses, it refuses with
// the same exception and error, logged on stdout. It answers no faster than a T7 over Ethernet:
// the link's overhead plus each input's sample time at its resolution index (t7_timing.hpp), and
// like a T7 it serves two Modbus TCP connections at once and closes a third.
//
// Its valve state can be read by tests and scripts from a status file (JSON, rewritten atomically
// at most every 10 ms and at every watchdog action, on a thread of its own so that the disk never
// delays an answer; docs/labjack-t7.md has its fields), and each
// watchdog action is also a line on stdout.
#pragma once

#include <array>
#include <cstdint>
#include <functional>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

#include "devices/latest_file_writer.hpp"
#include "devices/lcm_rig_limits.hpp"
#include "devices/rig_profile.hpp"
#include "devices/simulated_arm.hpp"
#include "devices/t7_sim_registers.hpp"
#include "devices/t7_timing.hpp"

typedef struct _modbus modbus_t;

namespace bellows {

struct T7SimOptions {
  std::string host = "127.0.0.1";
  int port = 5020;  // 0: any free port (port() tells which)
  RigProfile profile;
  PlantParameters plant;
  std::uint64_t seed = 1;
  bool swapped_chambers = false;              // chamber A's transmitter wired to chamber B's input and back
  std::optional<ValveRole> dead_valve;        // this valve pair never opens, whatever its line does
  bool no_supply = false;                     // the supply at ambient pressure
  double silent_after_s = -1.0;               // >= 0: the link goes silent this long after the first request
  double stall_after_s = -1.0;                // >= 0: this long after the first request, one answer comes late...
  double stall_s = 0.05;                      // ...by this long (the server stalls, as a busy network or T7 would)
  std::string status_path;                    // "": no status file
  t7::Product product = t7::Product::kT7Pro;  // paces the answers, bounds the resolution index
  bool nagle = false;                         // drill: keep Nagle's algorithm on the answers (a T7 does not)
  double answer_after_s = 0.0;                // drill: every answer this much later (a slow device)
  double trickle_after_s = -1.0;              // drill: this long after the first request, answers trickle...
  double trickle_byte_s = 0.4;                // ...one byte every this long (the link holds, barely)
  bool silent_reads = false;                  // drill: reads of the analog inputs go unanswered (no reading ever)
  bool streaming = false;                     // drill: another program streams (STREAM_ENABLE 1; AIN reads refused)
  double halve_roll_after_s = -1.0;           // drill: this long after the first request, clock 0's roll value halves
                                              // (another program reconfigured it): wide duty cycles are refused, 2565
  RigLimits limits;                           // the rig's own limits, enforced whatever the client writes
};

/// What the T7's lines output and what its watchdog did, for tests and scripts.
struct T7SimStatus {
  double time_s = 0.0;                         // since the server started
  std::array<double, kValveRoleCount> duty{};  // by ValveRole: the duty cycle its line outputs
  bool safe = true;                            // inlets closed, outlets open
  double safe_since_s = 0.0;                   // when the lines last became safe (-1: not safe)
  double last_request_s = -1.0;                // when a request was last answered (-1: never)
  bool watchdog_enabled = false;
  std::uint32_t watchdog_timeout_s = 0;
  int watchdog_actions = 0;
  double last_watchdog_action_s = -1.0;
  double first_watchdog_action_s = -1.0;  // of this silence: the watchdog acts again every timeout while it lasts
  std::uint64_t requests = 0;             // answered
  std::uint64_t exceptions = 0;           // answered with a Modbus exception
  std::uint64_t refusals = 0;             // of which for a LabJack rule (t7_sim_rules.hpp), not an address
  int last_refused_error = 0;             // LabJack's error number of the latest refusal (0: none)
  int max_clients = 0;                    // the most connections at once
  int refused_connections = 0;            // connections beyond the T7's limit, closed at once
  int clients = 0;                        // connected now
  std::uint64_t late_answers = 0;         // answers sent more than 0.5 ms after LabJack's time (this host woke late)
  double answer_late_max_s = 0.0;         // the latest of them, beyond LabJack's time
  bool silent = false;
  int stalls = 0;                                    // answers held back by the stall drill
  bool trickling = false;                            // the trickle drill has begun
  std::array<double, kActuatorCount> chamber_bar{};  // the arm's true chamber pressures, A and B
  double angle_rad = 0.0;                            // the arm's true angle
  int pressure_limit_trips = 0;                      // times a chamber reached the ceiling and was vented
  int angle_limit_trips = 0;                         // times the arm left the angle range and all was vented
};

class T7SimServer {
 public:
  /// Listens on host:port. Throws EnvironmentError when it cannot.
  explicit T7SimServer(T7SimOptions options);
  ~T7SimServer();
  T7SimServer(const T7SimServer&) = delete;
  T7SimServer& operator=(const T7SimServer&) = delete;

  int port() const { return port_; }
  /// Serves until `should_stop()` (checked at least every millisecond). `events` gets one line per
  /// watchdog action and per client that comes or goes.
  void run(const std::function<bool()>& should_stop, const std::function<void(const std::string&)>& events);
  T7SimStatus status() const;

 private:
  double now_s() const;
  void advance_arm(double now);
  void update_inputs();
  void apply_lines(double now);
  void apply_limits(bool write);
  void serve_client(int fd, double now, const std::function<void(const std::string&)>& events);
  void write_status(double now, bool force);
  /// The time a T7 takes to answer this request: the link's overhead, plus each input it reads.
  double answer_time_s(int function, int address, int count) const;
  void trickle_reply(int fd, int function, int address, int count);

  T7SimOptions options_;
  modbus_t* context_ = nullptr;
  int listen_fd_ = -1;
  int port_ = 0;
  std::vector<int> clients_;
  T7SimRegisters registers_;
  SimulatedArm arm_;
  double start_s_ = 0.0;
  double arm_time_s_ = 0.0;  // wall time the arm has been advanced to (since start)
  double first_request_s_ = -1.0;
  double busy_until_s_ = 0.0;  // when the last answer was due and left (the next queued one waits for it)
  bool roll_halved_ = false;
  double last_status_write_s_ = -1.0;
  T7SimStatus status_;  // the server thread's; published copies under the mutex
  mutable std::mutex published_mutex_;
  T7SimStatus published_;
  std::unique_ptr<LatestFileWriter> status_file_;  // null: no status file
  std::vector<std::uint8_t> query_;
  ValveCommand commanded_ = ValveCommand::vented();  // what the lines ask of the valves (a dead one shut)
  std::int32_t limit_bits_ = 0;                      // the limits acting now (kRig*LimitBit)
  const std::function<void(const std::string&)>* events_ = nullptr;  // run()'s, while it runs
};

}  // namespace bellows
