#include "app/device_factory.hpp"

#include <chrono>
#include <cstdio>
#include <thread>

#include <CLI/CLI.hpp>

#include "app/run_io.hpp"
#include "app/t7_wiring.hpp"
#include "engine/base/cancellation.hpp"
#include "devices/lcm_channels.hpp"
#include "devices/lcm_auth.hpp"
#include "devices/lcm_device.hpp"
#include "devices/lcm_io_thread.hpp"
#include "devices/simulated_arm_chain.hpp"
#include "engine/base/errors.hpp"
#include "engine/model/pneumatic_arm_chain_parameters.hpp"

namespace bellows {
namespace {

// The device's I/O thread runs just below the engine loop (priority 80): it carries the loop's
// sensor readings and valve commands.
constexpr int kDeviceIoPriority = 70;
// A rig serves this engine when a valid state of its session arrived this recently (10 ticks).
constexpr double kServedWithin_s = 0.05;

class SimulatedDevice final : public OpenedDevice {
 public:
  SimulatedDevice(const PlantParameters& plant, std::uint64_t seed) : arm_(plant, seed), seed_(seed) {}
  Device& device() override { return arm_; }
  SimulatedArm* simulated_arm() override { return &arm_; }
  bool needs_real_time() const override { return false; }
  nlohmann::ordered_json session_info() const override { return {{"seed", seed_}}; }
  std::string where() const override { return "in-process"; }

 private:
  SimulatedArm arm_;
  std::uint64_t seed_;
};

// The simulated arm of several joints ([arm] preset or its own keys), in-process like the single-joint one.
class SimulatedChainDevice final : public OpenedDevice {
 public:
  SimulatedChainDevice(const Configuration& config, std::uint64_t seed)
      : arm_(pneumatic_chain_of(config.plant, config.arm), seed), seed_(seed), arm_name_(config.arm.name()) {}
  Device& device() override { return arm_; }
  SimulatedArmChain* simulated_arm_chain() override { return &arm_; }
  bool needs_real_time() const override { return false; }
  nlohmann::ordered_json session_info() const override { return {{"seed", seed_}, {"arm", arm_name_}}; }
  std::string where() const override { return "in-process"; }

 private:
  SimulatedArmChain arm_;
  std::uint64_t seed_;
  std::string arm_name_;
};

class LcmRig final : public OpenedDevice {
 public:
  LcmRig(const std::string& url, RealtimeMode rt, std::int64_t session_id, LcmKey key, double rig_silence_s, int joints,
         const TickPhaseLock::Parameters& phase_lock)
      : device_(session_id, key, rig_silence_s, joints),
        io_(url.empty() ? kDefaultLcmUrl : url, std::vector<LcmEndpoint*>{&device_}) {
    device_.set_tick_phase_lock(phase_lock);
    io_.start(rt, kDeviceIoPriority);
  }
  ~LcmRig() override { io_.stop(); }
  Device& device() override { return device_; }
  LcmDevice* lcm_device() override { return &device_; }
  nlohmann::ordered_json session_info() const override {
    return {{"lcm", io_.url()}, {"session_id", device_.session_id()}};
  }
  std::string where() const override { return io_.url(); }
  void stop() override { io_.stop(); }

  std::string wait_until_served(double timeout_s, const std::atomic<bool>& stop) override {
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::duration<double>(timeout_s);
    const auto served = [&] { return device_.connected() && monotonic_s() - device_.last_state_s() < kServedWithin_s; };
    while (!served()) {
      if (stop.load(std::memory_order_relaxed)) return "interrupted while waiting for a rig";
      if (std::chrono::steady_clock::now() > deadline) {
        const LcmDeviceStats s = device_.stats();
        char why[320];
        if (s.states.unauthenticated > 0 && s.states.accepted == 0) {
          std::snprintf(why, sizeof why,
                        "a rig answers on %s but its states fail authentication (%llu): a different [lcm] key_file?",
                        io_.url().c_str(), static_cast<unsigned long long>(s.states.unauthenticated));
        } else if (s.states.other_joints > 0 && s.states.accepted == 0) {
          std::snprintf(why, sizeof why, "%s", device_.diagnosis().c_str());  // a rig of another arm, in one line
        } else if (s.states.old_version > 0 && s.states.accepted == 0) {
          std::snprintf(why, sizeof why,
                        "a rig answers on %s in protocol version 1, which this bellows no longer speaks: update it",
                        io_.url().c_str());
        } else if (s.states.foreign > 0 && s.last_foreign_session != 0) {
          std::snprintf(why, sizeof why, "a rig answers on %s but serves another session (%lld)", io_.url().c_str(),
                        static_cast<long long>(s.last_foreign_session));
        } else {
          std::snprintf(why, sizeof why,
                        "no rig answered on %s within %g s (is `bellows io-sim` or a rig driver running?)",
                        io_.url().c_str(), timeout_s);
        }
        return why;
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(10));
    }
    return "";
  }

  nlohmann::json report() const override {
    const LcmDeviceStats s = device_.stats();
    return {
        {"url", io_.url()},
        {"rig_id", s.rig_id},
        {"states", receive_counts_json(s.states)},
        {"rig_fault_states", s.rig_fault_states},
        {"last_fault_bits", s.last_fault_bits},
        {"last_trip_bits", s.last_trip_bits},
        {"commands_sent", s.commands_sent},
        {"vent_commands_sent", s.vent_commands_sent},
        {"publish_errors", s.publish_errors},
        {"longest_command_gap_ms", s.longest_command_gap_s * 1e3},
        {"authenticated", s.keyed},
        {"commands_not_ours", s.commands_not_ours},
        {"rig_refused", {{"foreign", s.rig_foreign_commands}, {"unauthenticated", s.rig_unauthenticated_commands}}},
        {"tick_phase", {{"lead_ms", device_.tick_phase_lead_ms()}, {"shifted_ms", device_.tick_phase_shifted_ms()}}}};
  }

 private:
  LcmDevice device_;
  LcmIoThread io_;
};

// The LabJack T7 over Modbus TCP (app/t7_wiring): connected and configured at open; its I/O thread
// is the T7Device's own.
class T7Rig final : public OpenedDevice {
 public:
  explicit T7Rig(std::unique_ptr<T7Device> device) : device_(std::move(device)) {}
  ~T7Rig() override { device_->stop(); }
  Device& device() override { return *device_; }
  nlohmann::ordered_json session_info() const override {
    return {{"t7", device_->address()}, {"rig_profile", device_->profile().name}};
  }
  std::string rig_profile_name() const override { return device_->profile().name; }
  std::string where() const override { return device_->address(); }
  void stop() override { device_->stop(); }
  std::optional<double> angle_zero_rad() const override { return device_->angle_zero_rad(); }
  void set_angle_zero_rad(double zero_rad) override { device_->set_angle_zero_rad(zero_rad); }

  // Served: a reading came through the link after this call (not the zeros of one that never came).
  std::string wait_until_served(double timeout_s, const std::atomic<bool>& stop) override {
    if (device_->wait_for_reading(timeout_s, stop)) return "";
    if (stop.load(std::memory_order_relaxed)) return "interrupted while waiting for the T7";
    const std::string why = device_->link_error();
    return "no reading from the T7 at " + device_->address() + " within " + std::to_string(timeout_s).substr(0, 4) +
           " s" + (why.empty() ? std::string() : " (" + why + ")");
  }

  nlohmann::json report() const override {
    return {{"t7", device_->address()},
            {"product", t7::to_string(device_->product())},
            {"late_answers", device_->late_answers()},
            {"late_readings", device_->late_readings()},
            {"reconnects", device_->reconnects()},
            {"link_error", device_->link_error()}};
  }

 private:
  std::unique_ptr<T7Device> device_;
};

std::unique_ptr<OpenedDevice> open_t7(const DeviceParameters& device, const Configuration& config, RealtimeMode rt) {
  if (device.t7_address.empty()) throw InputError("--device t7 needs --t7 HOST[:PORT]");
  return std::make_unique<T7Rig>(
      open_t7_device({device.t7_address, device.rig_profile, rt != RealtimeMode::kOff}, config));
}

}  // namespace

void add_device_options(CLI::App& command, DeviceOptions& options, bool with_lcm) {
  command
      .add_option("--device", options.kind,
                  "The rig: sim (the simulated arm), lcm (a rig over LCM), t7 (a LabJack T7); default [device] kind")
      ->check(CLI::IsMember({"sim", "lcm", "t7"}));
  if (with_lcm)
    command.add_option("--lcm", options.lcm_url, "--device lcm: the rig's LCM bus URL (default [device] lcm)");
  command.add_option("--t7", options.t7_address, "--device t7: the T7's address HOST[:PORT] (port 502 by default)");
  command.add_option("--rig-profile", options.rig_profile,
                     "--device t7: the rig profile file (default: the paper's rig)");
}

DeviceParameters resolve_device(const DeviceOptions& given, const DeviceParameters& configured) {
  DeviceParameters d = configured;
  if (!given.kind.empty()) d.kind = given.kind;
  if (!given.lcm_url.empty()) d.lcm_url = given.lcm_url;
  if (!given.t7_address.empty()) d.t7_address = given.t7_address;
  if (!given.rig_profile.empty()) d.rig_profile = given.rig_profile;
  if (d.kind != "sim" && d.kind != "lcm" && d.kind != "t7") {
    throw InputError("--device '" + d.kind + "': unknown device (known: sim, lcm, t7)");
  }
  if (d.kind != "t7" && (!given.t7_address.empty() || !given.rig_profile.empty())) {
    throw InputError("--t7 and --rig-profile are for --device t7, not " + d.kind);
  }
  return d;
}

/// "[arm] preset = 'arm2'" or "[arm] joints = 3": what the operator wrote.
static std::string arm_setting(const ArmParameters& arm) {
  return !arm.preset.empty() ? "[arm] preset = '" + arm.preset + "'" : arm.name();
}

void require_served(OpenedDevice& rig, double timeout_s, const std::atomic<bool>& stop) {
  const std::string why = rig.wait_until_served(timeout_s, stop);
  if (why.empty()) return;
  if (stop.load(std::memory_order_relaxed)) throw Cancelled(why);
  throw EnvironmentError(why);
}

void require_driven_arm(const ArmParameters& arm, const std::string& device_kind) {
  if (arm.has_chain() && device_kind != "sim" && device_kind != "lcm") {  // the T7 link carries one joint
    throw InputError(arm_setting(arm) + ": an arm of several joints runs on --device sim or lcm; --device " +
                     device_kind + " drives one joint (leave [arm] out)");
  }
}

void require_single_joint_arm(const ArmParameters& arm, const std::string& what) {
  if (arm.has_chain()) throw InputError(arm_setting(arm) + ": " + what + " (leave [arm] out)");
}

std::unique_ptr<OpenedDevice> open_device(const DeviceParameters& device, const Configuration& config,
                                          std::uint64_t seed, RealtimeMode rt, std::int64_t session_id,
                                          const std::filesystem::path& config_dir) {
  require_driven_arm(config.arm, device.kind);
  if (device.kind == "sim" && config.arm.has_chain()) return std::make_unique<SimulatedChainDevice>(config, seed);
  if (device.kind == "sim") return std::make_unique<SimulatedDevice>(config.plant, seed);
  if (device.kind == "lcm") {
    return std::make_unique<LcmRig>(device.lcm_url, rt, session_id != 0 ? session_id : LcmDevice::random_session_id(),
                                    load_lcm_key(config.lcm.key_file, config_dir), config.lcm.rig_timeout_s,
                                    arm_joint_count(config.arm),
                                    TickPhaseLock::Parameters::of(config.timing, config.lcm));
  }
  if (device.kind == "t7") return open_t7(device, config, rt);
  throw InputError("--device '" + device.kind + "': unknown device (known: sim, lcm, t7)");
}

}  // namespace bellows
