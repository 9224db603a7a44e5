// A LabJack T7 over Modbus TCP (`--device t7`, docs/labjack-t7.md).
//
// The constructor connects, checks that a T7 answers and configures it: the T7's own watchdog
// (the backstop: it puts the valve lines in their safe state after watchdog_timeout_s of silence,
// even when bellows was killed), the analog input ranges, the PWM clock and the four PWM lines,
// vented. Then an I/O thread of its own does all Modbus traffic; the engine thread only touches
// lock-free latest-value buffers:
// - write_valves()/vent() leave the desired duty cycles in the outbox;
// - each new command makes the I/O thread do one exchange: one write of the four duty cycles and
//   one read of every analog input, then it hands the calibrated reading to read_sensors().
// So the engine's tick costs no system call, and there is at most one write and one read per tick.
// One exchange has one deadline, [t7] response_timeout_s for the write and the read together, so a
// vent never waits behind a stuck exchange for longer than that. A failed or timed-out exchange
// hands nothing over: the engine sees stale readings and, after [safety] stale_ticks of them,
// faults and vents. A late answer is matched by its transaction id on the same connection
// (devices/modbus_client.hpp): the late read's, when it comes before the next command, is still
// handed over (a reading of a moment ago, usually in time for the next tick); any other is dropped.
// Only a lost connection is opened again, the old one closed first. A Modbus exception names the register and LabJack's
// error (link_error()). Without commands (the engine not running) the I/O thread vents after [t7] command_timeout_s and
// keeps reading every tick, which keeps the watchdog fed and raw_inputs() live.
#pragma once

#include <array>
#include <atomic>
#include <memory>
#include <string>
#include <thread>
#include <vector>

#include "devices/io_turn_watch.hpp"
#include "devices/modbus_client.hpp"
#include "devices/rig_profile.hpp"
#include "devices/t7_registers.hpp"
#include "devices/t7_timing.hpp"
#include "engine/control/device.hpp"
#include "engine/rt/latest_value.hpp"
#include "engine/base/parameters.hpp"

namespace bellows {

struct T7DeviceOptions {
  std::string host = "127.0.0.1";
  int port = 502;
  RigProfile profile;
  T7Parameters link;
  double tick_s = 1.0 / 200.0;  // the idle exchange period
  bool realtime = true;         // ask for SCHED_FIFO for the I/O thread (ignored when refused)
  int priority = 70;            // just below the engine loop
  /// While connecting and configuring: set (SIGINT, SIGTERM) ends the constructor at once with
  /// Cancelled, nothing armed. Null: it cannot be interrupted.
  const std::atomic<bool>* stop = nullptr;
};

class T7Device final : public Device {
 public:
  /// Checks that the profile's exchange fits the tick (InputError, before any traffic), then connects
  /// and configures within [t7] connect_timeout_s in all. Throws EnvironmentError when the address
  /// cannot be reached, does not answer as a T7 in time, or refuses the configuration (the message
  /// names the address, the register and LabJack's error); Cancelled when options.stop was set.
  explicit T7Device(T7DeviceOptions options);
  /// Vents (one last write of the duty cycles) and closes the link.
  ~T7Device() override;
  /// Stops the I/O thread after its last exchange, which vents; the engine loop must have stopped.
  /// Idempotent (the destructor calls it).
  void stop();

  // ---- Device: engine thread ----
  SensorReading read_sensors() override;
  void write_valves(const ValveCommand& command) override;
  void vent() override;
  void advance(double) override {}  // a real rig's time passes on its own
  const char* name() const override { return "t7"; }

  // ---- any thread ----
  DeviceHealth health() const override;
  RawInputs raw_inputs() const override;
  /// A request the T7 refused during the run reaches the engine as `device-error`, naming the
  /// register and LabJack's error (take_refusal). Engine thread; allocates nothing.
  bool take_fault(DeviceFault& fault) override;
  /// Silent for the stale limit: `link-lost` "this host's T7 I/O thread did not run" when the I/O
  /// thread made no turn for (half) that time and longer than an exchange's deadline (the host held it
  /// off its core); `link-lost` naming the address when nothing at all came from the T7 for (half)
  /// that time; `sensor-stale` "answers, but late" when bytes came but no answer in time; else the
  /// default `sensor-stale`.
  void explain_silence(double silent_s, DeviceFault& fault) const override;
  /// "host:port".
  const std::string& address() const { return address_; }
  const RigProfile& profile() const { return options_.profile; }
  /// The angle's zero in use: the profile's, until the first day's zeroing sets a new one, which
  /// the readings take from their next exchange on.
  double angle_zero_rad() const { return angle_zero_rad_.load(std::memory_order_relaxed); }
  void set_angle_zero_rad(double zero_rad) { angle_zero_rad_.store(zero_rad, std::memory_order_relaxed); }
  /// Why the link failed ("" while it works). Set once, by the I/O thread.
  std::string link_error() const;
  /// The product that answered: T7 or T7-Pro (HARDWARE_INSTALLED's high-resolution ADC).
  t7::Product product() const { return product_; }
  /// Answers to timed-out requests dropped by transaction id, and connections opened again.
  std::uint64_t late_answers() const { return late_answers_.load(std::memory_order_relaxed); }
  std::uint64_t reconnects() const { return reconnects_.load(std::memory_order_relaxed); }
  /// Readings of exchanges that missed their deadline, handed over when their answer came after all.
  std::uint64_t late_readings() const { return late_readings_.load(std::memory_order_relaxed); }
  /// A request the T7 refused during the run (a Modbus exception): once per refusal, its sentence
  /// naming the register and LabJack's error ("t7 HOST:PORT: writing DIO2_EF_CONFIG_A (44304)
  /// refused: ..., LabJack error 2565 EF_VALUE_GREATER_THAN_PERIOD"), for the engine's
  /// device-error fault (take_fault). Engine thread; allocates nothing.
  static constexpr std::size_t kRefusalChars = 192;
  bool take_refusal(std::array<char, kRefusalChars>& text);
  /// Whether the link answered at all lately (false: it is down, not only frozen), for the
  /// engine's link-lost fault; any thread.
  bool link_answers() const { return link_up_.load(std::memory_order_acquire); }
  /// Waits until the I/O thread has handed over a reading made after this call, at most
  /// `timeout_s`; false when none came (link_error() may say why) or *stop was set.
  bool wait_for_reading(double timeout_s, const std::atomic<bool>& stop) const;

 private:
  static std::string seconds_text(double s);                           // "2 s"
  static double duty_of(const ValveCommand& command, ValveRole role);  // the duty a command gives a valve line
  struct Outgoing {
    ValveCommand valves = ValveCommand::vented();
  };

  // The configuration sequence, in t7_device_configure.cpp.
  void configure();
  void configure_watchdog();
  void require(bool ok, const char* what, int address);
  std::string refusal(const char* what, int address);
  void configure_inputs();
  void configure_clock();
  void configure_lines();
  void serve();
  bool exchange(const ValveCommand& valves);
  /// The reading in ain_buffer_, answered at `end` (steady clock), to the engine.
  void publish_reading(double end);
  void encode_duties(const ValveCommand& valves);
  /// client_.take_late_read() into ain_buffer_, noting what was heard.
  bool take_late_read();
  void record_round_trip(double ms);
  void fail_link(const std::string& why);

  T7DeviceOptions options_;
  std::atomic<double> angle_zero_rad_;
  std::string address_;
  ModbusClient client_;
  t7::PwmClock clock_;
  t7::Product product_ = t7::Product::kT7Pro;
  int first_dio_ = 0, dio_span_ = 0;  // the CONFIG_A block written each exchange
  int ain_registers_ = 0;             // AIN0.. up to the highest input used, two registers each

  LatestValue<Outgoing> outbox_;      // engine -> I/O
  LatestValue<SensorReading> inbox_;  // I/O -> engine
  SensorReading reading_{};           // engine thread's copy

  // I/O thread state (preallocated: the thread allocates nothing per exchange).
  std::vector<std::uint16_t> duty_registers_;
  std::vector<std::uint16_t> ain_buffer_;
  std::vector<double> round_trips_ms_;  // ring of the latest exchanges
  std::vector<double> scratch_ms_;
  std::size_t round_trip_count_ = 0;
  double origin_s_ = 0.0;
  double last_time_s_ = 0.0;
  double exchange_start_s_ = 0.0;  // the latest exchange's (a late reading's round trip counts from it)

  std::thread thread_;
  std::atomic<bool> stop_{false};
  std::atomic<bool> link_up_{true};
  std::atomic<bool> error_published_{false};
  std::string link_error_;                          // written once before error_published_
  std::array<char, kRefusalChars> refusal_text_{};  // written by the I/O thread while !refusal_pending_
  std::atomic<bool> refusal_pending_{false};
  std::array<std::atomic<double>, kSensorRoleCount> volts_{};
  std::atomic<double> p50_ms_{0.0}, p99_ms_{0.0}, max_ms_{0.0};
  std::atomic<std::uint64_t> exchanges_{0}, link_errors_{0}, stale_readings_{0}, late_answers_{0}, reconnects_{0},
      late_readings_{0};
  std::atomic<double> heard_s_{-1e300};  // the client's last_receive_s(), copied by the I/O thread
  IoTurnWatch io_turns_;                 // the I/O thread's turns, on now_s() (explain_silence())
};

}  // namespace bellows
