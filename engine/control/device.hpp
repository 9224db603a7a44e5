// The device interface: what the engine needs from a rig, simulated or real.
// devices/ implements it; the engine never knows which one it drives.
#pragma once

#include <array>
#include <cstdint>

#include "engine/base/joints.hpp"
#include "engine/control/fault_code.hpp"

namespace bellows {

inline constexpr int kActuatorCount = 2;  // per joint: A (index 0) and B (index 1)

/// One joint's sensors: its encoder and its two chambers.
struct JointReading {
  double angle_rad = 0.0;                            // encoder, quantized by the device
  std::array<double, kActuatorCount> chamber_bar{};  // absolute pressures of A and B
};

/// One reading of every sensor, taken at the start of a tick. Fixed capacity (kMaxJoints joints,
/// no allocation); joints [0, joint_count) are read, the rest stay zero. Supply and temperature
/// are shared by all joints.
///
/// "No reading this tick": a device with nothing new returns its last reading again, with the same
/// `time_s` (a reading is fresh exactly when its time_s is above the last one the engine saw). The
/// engine then holds the valves (inlets and outlets closed: nothing can inflate) and runs no
/// controller on it; [safety] stale_ticks such ticks in a row are a fault, named by
/// Device::explain_silence().
struct SensorReading {
  double time_s = 0.0;  // device time of the reading
  int joint_count = 1;
  std::array<JointReading, kMaxJoints> joint{};
  double supply_bar = 0.0;     // absolute supply pressure
  double temperature_K = 0.0;  // supply temperature
};

/// One joint's valves for one PWM period: duty cycles in [0, 1] per actuator.
struct JointValves {
  std::array<double, kActuatorCount> inlet_duty{};
  std::array<double, kActuatorCount> outlet_duty{};
};

/// The full desired valve state for one PWM period, per joint. Fixed capacity like SensorReading:
/// joints [0, joint_count) are commanded. Default: every valve closed (the chambers keep their air).
struct ValveCommand {
  int joint_count = 1;
  std::array<JointValves, kMaxJoints> joint{};

  /// Inlets closed, outlets fully open on every joint, also beyond `joint_count` (a device that
  /// reads more joints than the command names still vents them): the safe state.
  static ValveCommand vented(int joint_count = 1) {
    ValveCommand c;
    c.joint_count = joint_count;
    for (JointValves& j : c.joint) j.outlet_duty = {1.0, 1.0};
    return c;
  }
};

/// What a device with one joint applies of `command`: joint 0's valves, or vented ones when the
/// command is for another number of joints (meant for another arm: nothing of it is safe to apply).
inline JointValves single_joint_valves(const ValveCommand& command) {
  return command.joint_count == 1 ? command.joint[0] : ValveCommand::vented().joint[0];
}

/// How the link to a rig is doing (all zero for an in-process device). The round trip is one
/// exchange with the rig (for a T7: one read of the inputs and one write of the duties).
struct DeviceHealth {
  bool has_link = false;   // false: in-process, nothing to report
  bool connected = false;  // the link answers
  double round_trip_p50_ms = 0.0;
  double round_trip_p99_ms = 0.0;
  double round_trip_max_ms = 0.0;
  std::uint64_t exchanges = 0;       // completed exchanges
  std::uint64_t link_errors = 0;     // failed or timed-out exchanges
  std::uint64_t stale_readings = 0;  // reads that brought nothing new
};

/// How long after a command a reading shows it: the round trip's p99 (0 in process).
inline double link_lag_s(const DeviceHealth& health) { return health.has_link ? health.round_trip_p99_ms / 1e3 : 0.0; }

/// One analog input as the rig sees it: the raw volts and the calibrated value (rig bring-up).
struct RawInput {
  const char* name = "";  // e.g. "chamber_a" (static storage)
  const char* unit = "";  // unit of `value`: "bar", "deg", "K"
  double volts = 0.0;
  double value = 0.0;
};
inline constexpr int kMaxRawInputs = 8;
struct RawInputs {
  std::array<RawInput, kMaxRawInputs> inputs{};
  int count = 0;
};

/// A rig. Calls come from the engine thread only; implementations must not block for long
/// (except `health()` and `raw_inputs()`, which any thread may call: they read latest values).
class Device {
 public:
  virtual ~Device() = default;
  /// Latest sensor values.
  virtual SensorReading read_sensors() = 0;
  /// Apply a valve command for the coming PWM period. Duty cycles are clamped to [0, 1].
  virtual void write_valves(const ValveCommand& command) = 0;
  /// Close every inlet and open every outlet at once.
  virtual void vent() = 0;
  /// Let device time pass by `dt_s`. A simulated device integrates its physics here;
  /// a real rig ignores it (its time passes on its own).
  virtual void advance(double dt_s) = 0;
  /// Whether the device's time passes only by advance(), once per engine tick (an in-process
  /// simulation): then a late tick harms nothing physical and a missed deadline is a warning.
  /// A real or remote rig keeps the default: its time passes on its own, a missed deadline faults.
  virtual bool time_follows_ticks() const { return false; }
  /// How much later (s; negative: earlier) the engine's next tick should start than one period
  /// after this one. A rig that publishes its states on a clock of its own asks for the ticks to
  /// read each state a safe margin after it arrives (LcmDevice; docs/lcm-protocol.md "Timing");
  /// the loop takes at most a tenth of a period. Engine thread, once after every tick. Default 0.
  virtual double tick_shift_s() { return 0.0; }
  /// A short human name, e.g. "sim" or "lcm".
  virtual const char* name() const = 0;
  /// The link's figures; any thread. In-process devices report nothing.
  virtual DeviceHealth health() const { return {}; }
  /// The raw inputs beside their calibrated values; any thread. Empty where there are no volts.
  virtual RawInputs raw_inputs() const { return {}; }

  // ---- faults the device finds itself (engine thread, every tick; neither may allocate) ----
  /// A fault the device found since the last call: the rig's own trip with its reason and joint
  /// (kRigLimit, kRigTimeout, kRigFault), a refused request (kDeviceError), a link it knows is gone
  /// (kLinkLost). Fills `fault` and returns true once per fault; the engine latches it (venting)
  /// while the valves are live and ignores it otherwise. Default: none.
  virtual bool take_fault(DeviceFault& fault) {
    (void)fault;
    return false;
  }
  /// Why no fresh reading came for `silent_s` (the engine's stale limit reached): asked once, just
  /// before the engine faults. A device with a link that heard nothing at all in that time says
  /// kLinkLost, naming itself (the rig, the address) and how long it has been silent; one whose
  /// link answers with frozen values leaves the default, kSensorStale.
  virtual void explain_silence(double silent_s, DeviceFault& fault) const {
    fault.set(FaultCode::kSensorStale, -1, "no fresh reading for %.0f ms: %s", silent_s * 1e3,
              fault_message(FaultCode::kSensorStale));
  }
};

}  // namespace bellows
