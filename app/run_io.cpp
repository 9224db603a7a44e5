#include "app/run_io.hpp"

#include <chrono>
#include <cstdio>
#include <thread>

#include "app/t7_wiring.hpp"
#include "devices/lcm_channels.hpp"
#include "engine/errors.hpp"

namespace bellows {
namespace {

// The device's I/O thread runs just below the engine loop (priority 80): it carries the loop's
// sensor readings and valve commands.
constexpr int kDeviceIoPriority = 70;
// Telemetry taps hold this many seconds of ticks; the publisher drains them every 20 ms.
constexpr double kTelemetryRing_s = 1.0;
// A rig serves this run when a valid state of its session arrived this recently (10 ticks).
constexpr double kServedWithin_s = 0.05;
// The LCM log's name inside a session directory (a resumed session gets the next free number).
constexpr const char* kSessionLogStem = "telemetry";

std::string free_log_name(const std::filesystem::path& directory) {
  std::filesystem::path path = directory / (std::string(kSessionLogStem) + ".lcmlog");
  for (int n = 2; std::filesystem::exists(path); ++n) {
    path = directory / (std::string(kSessionLogStem) + "-" + std::to_string(n) + ".lcmlog");
  }
  return path.string();
}

}  // namespace

nlohmann::json receive_counts_json(const ReceiveCounts& c) {
  return {{"accepted", c.accepted},
          {"ignored",
           {{"truncated", c.truncated},
            {"wrong_type", c.wrong_type},
            {"too_large", c.too_large},
            {"malformed", c.malformed},
            {"invalid", c.invalid},
            {"foreign", c.foreign},
            {"out_of_order", c.out_of_order}}}};
}

RunIo::RunIo(const RunOptions& options, double speed, std::uint64_t seed, const Configuration& config)
    : options_(options), config_(config), telemetry_(!options.lcm_url.empty() || options.lcm_log) {
  if (options.device != "sim" && options.device != "lcm" && options.device != "t7") {
    throw InputError("--device must be sim, lcm or t7, not '" + options.device + "'");
  }
  if (options.device != "t7" && (!options.t7_address.empty() || !options.rig_profile.empty())) {
    throw InputError("--t7 and --rig-profile go with --device t7");
  }
  if (options.lcm_log && options.lcm_log_file.empty() && options.no_save) {
    throw InputError("--lcm-log without a FILE writes into the session directory: name a FILE with --no-save");
  }
  if (options.lcm_log && !options.lcm_log_file.empty() && std::filesystem::exists(options.lcm_log_file)) {
    throw InputError("the LCM log '" + options.lcm_log_file + "' exists already; nothing is overwritten, name a new file");
  }
  if (options.device == "lcm" || options.device == "t7") {
    const std::string flag = "--device " + options.device;
    if (options.clock != "wall") {
      throw InputError(flag + " needs --clock wall: a real rig's time passes on its own and cannot be simulated");
    }
    if (speed != 1.0) throw InputError(flag + " runs in real time: --speed must be 1");
    if (!options.resume_dir.empty()) throw InputError("--resume continues a session on the simulated arm; it cannot go with " + flag);
  }
  if (options.device == "t7") {
    if (options.t7_address.empty()) throw InputError("--device t7 needs --t7 HOST[:PORT]");
    t7_device_ = open_t7_device({options.t7_address, options.rig_profile, options.rt != RealtimeMode::kOff}, config);
  }
  if (options.device == "lcm" || telemetry_) session_id_ = LcmDevice::random_session_id();
  if (options.device == "sim") {
    arm_ = std::make_unique<SimulatedArm>(config.plant, seed);
    return;
  }
  if (options.device == "t7") return;
  lcm_device_ = std::make_unique<LcmDevice>(session_id_);
  const std::string url = options.lcm_url.empty() ? kDefaultLcmUrl : options.lcm_url;
  device_io_ = std::make_unique<LcmIoThread>(url, std::vector<LcmEndpoint*>{lcm_device_.get()});
  device_io_->start(options.rt, kDeviceIoPriority);
}

RunIo::~RunIo() { stop(); }

Device& RunIo::device() {
  if (t7_device_) return *t7_device_;
  if (lcm_device_) return *lcm_device_;
  return *arm_;
}

void RunIo::add_telemetry_tap(EngineCore& core) {
  if (!telemetry_) return;
  tap_ = &core.add_telemetry_tap(static_cast<std::size_t>(kTelemetryRing_s / config_.timing.tick_s) + 1);
}

std::unique_ptr<SimulatedClock> RunIo::simulated_clock(EngineCore& core) {
  auto clock = std::make_unique<SimulatedClock>(core, device());
  clock->pace_by(tap_);  // null without telemetry
  return clock;
}

void RunIo::start_telemetry(const std::filesystem::path& session_directory) {
  if (tap_ == nullptr) return;
  if (options_.lcm_log) log_path_ = !options_.lcm_log_file.empty() ? options_.lcm_log_file : free_log_name(session_directory);
  publisher_ = std::make_unique<TelemetryPublisher>(*tap_, session_id_, log_path_);
  publisher_io_ = std::make_unique<LcmIoThread>(options_.lcm_url, std::vector<LcmEndpoint*>{publisher_.get()});
  publisher_io_->start(RealtimeMode::kOff, 0);  // telemetry is not real-time
}

std::string RunIo::wait_for_rig(const std::atomic<bool>& stop) {
  if (!lcm_device_) return "";
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::duration<double>(config_.lcm.connect_timeout_s);
  // Served now: a valid state of this session within the last few ticks.
  const auto served = [&] {
    return lcm_device_->connected() && monotonic_s() - lcm_device_->last_state_s() < kServedWithin_s;
  };
  while (!served()) {
    if (stop.load(std::memory_order_relaxed)) return "interrupted while waiting for a rig";
    if (std::chrono::steady_clock::now() > deadline) {
      const LcmDeviceStats s = lcm_device_->stats();
      char why[320];
      if (s.states.foreign > 0 && s.last_foreign_session != 0) {
        std::snprintf(why, sizeof why, "a rig answers on %s but serves another session (%lld)", device_io_->url().c_str(),
                      static_cast<long long>(s.last_foreign_session));
      } else {
        std::snprintf(why, sizeof why, "no rig answered on %s within %g s (is `bellows io-sim` or a rig driver running?)",
                      device_io_->url().c_str(), config_.lcm.connect_timeout_s);
      }
      return why;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  return "";
}

void RunIo::post_trial(const IterationSummary& summary, const Eigen::VectorXd& correction_bar) {
  if (publisher_) publisher_->post_trial(summary, correction_bar, config_.timing.sample_s());
}

void RunIo::stop() {
  if (device_io_) device_io_->stop();
  if (publisher_io_) publisher_io_->stop();
}

nlohmann::json RunIo::report() const {
  if (session_id_ == 0) return nullptr;
  nlohmann::json lcm = {{"session_id", session_id_}};
  if (!options_.lcm_url.empty()) lcm["url"] = options_.lcm_url;
  if (lcm_device_) {
    const LcmDeviceStats s = lcm_device_->stats();
    lcm["rig"] = {{"url", device_io_->url()},
                  {"rig_id", s.rig_id},
                  {"states", receive_counts_json(s.states)},
                  {"rig_fault_states", s.rig_fault_states},
                  {"last_fault_bits", s.last_fault_bits},
                  {"commands_sent", s.commands_sent},
                  {"vent_commands_sent", s.vent_commands_sent},
                  {"publish_errors", s.publish_errors}};
  }
  if (publisher_) {
    const TelemetryPublisherStats s = publisher_->stats();
    lcm["telemetry"] = {{"ticks", s.ticks},
                        {"dropped_ticks", s.dropped_ticks},
                        {"events", s.events},
                        {"trials", s.trials},
                        {"log_events", s.log_events},
                        {"errors", s.errors}};
    if (!log_path_.empty()) lcm["telemetry"]["log"] = log_path_;
  }
  return lcm;
}

std::string RunIo::warning() const {
  if (!publisher_) return "";
  const TelemetryPublisherStats s = publisher_->stats();
  if (s.dropped_ticks == 0 && s.errors == 0) return "";
  return "telemetry: " + std::to_string(s.dropped_ticks) + " ticks dropped, " + std::to_string(s.errors) +
         " publish or log errors";
}

}  // namespace bellows
