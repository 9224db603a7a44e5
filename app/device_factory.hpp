// The one place a command opens its rig: `bellows console`, `run`, `identify` and `rig check` take
// the same device options (--device sim|lcm|t7, --lcm URL, --t7 HOST[:PORT], --rig-profile FILE,
// over the configuration's [device] section) and get the same device, with its I/O thread running.
#pragma once

#include <atomic>
#include <cstdint>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>

#include <nlohmann/json.hpp>

#include "devices/simulated_arm.hpp"
#include "devices/simulated_arm_chain.hpp"
#include "engine/config/configuration.hpp"
#include "engine/control/device.hpp"
#include "engine/rt/realtime_loop.hpp"

namespace CLI {
class App;
}

namespace bellows {

class LcmDevice;

/// The device options as given on the command line; an empty field takes the [device] value.
struct DeviceOptions {
  std::string kind;         // --device
  std::string lcm_url;      // --lcm
  std::string t7_address;   // --t7
  std::string rig_profile;  // --rig-profile
};

/// Adds --device, --t7, --rig-profile and (unless the command has its own) --lcm to `command`.
void add_device_options(CLI::App& command, DeviceOptions& options, bool with_lcm = true);

/// The [device] section with the command line on top; checks the kind (InputError).
DeviceParameters resolve_device(const DeviceOptions& given, const DeviceParameters& configured);

/// A device opened for one command: the Device the engine drives and whatever runs beside it.
class OpenedDevice {
 public:
  virtual ~OpenedDevice() = default;
  virtual Device& device() = 0;
  /// The simulated arm (sim only), else null.
  virtual SimulatedArm* simulated_arm() { return nullptr; }
  /// The simulated arm of several joints (sim with an [arm] preset), else null.
  virtual SimulatedArmChain* simulated_arm_chain() { return nullptr; }
  /// A real rig's time passes on its own: only the wall clock at speed 1 can drive it.
  virtual bool needs_real_time() const { return true; }
  /// Waits (the engine loop running) until the rig serves this engine; "" when it does, else why
  /// not. Gives up early when `stop` is set.
  virtual std::string wait_until_served(double timeout_s, const std::atomic<bool>& stop) {
    (void)timeout_s;
    (void)stop;
    return "";
  }
  /// What the session records about the device besides its name (seed, bus, address, rig profile).
  virtual nlohmann::ordered_json session_info() const = 0;
  /// The rig profile's name ("" without one): recorded in sessions and shown by the console.
  virtual std::string rig_profile_name() const { return ""; }
  /// A one-line description of the link for the operator ("udpm://...", "192.168.1.10:502").
  virtual std::string where() const { return ""; }
  /// Counters for a JSON report (null when there are none).
  virtual nlohmann::json report() const { return nullptr; }
  /// Zeroing the angle (the first day): the zero in use, where the device has one (t7), and a new
  /// one, which the readings take from then on. A device without one keeps nothing.
  virtual std::optional<double> angle_zero_rad() const { return std::nullopt; }
  virtual void set_angle_zero_rad(double zero_rad) { (void)zero_rad; }
  /// The LCM rig's device (--device lcm), else null: `rig check` provokes its command timeout.
  virtual LcmDevice* lcm_device() { return nullptr; }
  /// Stops the I/O thread (the rig's last vent goes out). Idempotent.
  virtual void stop() {}
};

/// Waits until `rig` serves this engine (OpenedDevice::wait_until_served). Throws Cancelled when
/// `stop` was set (the command exits 128 + signal, nothing armed), else EnvironmentError saying why.
void require_served(OpenedDevice& rig, double timeout_s, const std::atomic<bool>& stop);

/// Refuses, in one line, an arm `device_kind` cannot drive: an [arm] preset of several joints runs on
/// the simulated arm and over LCM (the joint messages), not on a T7.
void require_driven_arm(const ArmParameters& arm, const std::string& device_kind);
/// Refuses, in one line, an [arm] preset for a command that handles one joint (`what`, e.g.
/// "`bellows identify` identifies one joint").
void require_single_joint_arm(const ArmParameters& arm, const std::string& what);

/// Opens the device `device` names. `seed`: the simulated arm's noise; `rt`: the I/O thread's
/// scheduling; `session_id`: the LCM session (0: a random one); `config_dir`: where a relative
/// [lcm] key_file is found (the configuration file's folder). Throws InputError for bad options (and a
/// device this build does not have), EnvironmentError for a bus that cannot be opened.
std::unique_ptr<OpenedDevice> open_device(const DeviceParameters& device, const Configuration& config,
                                          std::uint64_t seed, RealtimeMode rt, std::int64_t session_id,
                                          const std::filesystem::path& config_dir = {});

}  // namespace bellows
