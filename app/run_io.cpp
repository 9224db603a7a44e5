#include "app/run_io.hpp"

#include <chrono>
#include <cstdio>
#include <thread>

#include "app/device_factory.hpp"
#include "devices/lcm_channels.hpp"
#include "engine/base/errors.hpp"
#include "sessions/atomic_file.hpp"

namespace bellows {
namespace {

// Telemetry taps hold this many seconds of ticks; the publisher drains them every 20 ms.
constexpr double kTelemetryRing_s = 1.0;
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
          {"offers", c.offers},
          {"ignored",
           {{"truncated", c.truncated},
            {"wrong_type", c.wrong_type},
            {"too_large", c.too_large},
            {"malformed", c.malformed},
            {"invalid", c.invalid},
            {"foreign", c.foreign},
            {"out_of_order", c.out_of_order},
            {"old_version", c.old_version},
            {"unauthenticated", c.unauthenticated},
            {"other_joints", c.other_joints}}}};
}

RunIo::RunIo(const RunOptions& options, double speed, std::uint64_t seed, const Configuration& config)
    : options_(options), config_(config), telemetry_(!options.lcm_url.empty() || options.lcm_log) {
  device_parameters_ = resolve_device(options.device, config.device);
  const std::string& kind = device_parameters_.kind;
  if (kind == "lcm" && device_parameters_.lcm_url.empty())
    device_parameters_.lcm_url = options.lcm_url;  // --lcm: the bus of both
  if (options.lcm_log && options.lcm_log_file.empty() && options.no_save) {
    throw InputError("--lcm-log without a FILE writes into the session directory: name a FILE with --no-save");
  }
  std::error_code missing;  // a link counts as existing, also a dangling one: nothing is written through it
  if (options.lcm_log && !options.lcm_log_file.empty() &&
      std::filesystem::symlink_status(options.lcm_log_file, missing).type() != std::filesystem::file_type::not_found) {
    throw InputError("the LCM log '" + options.lcm_log_file +
                     "' exists already; nothing is overwritten, name a new file");
  }
  if (kind != "sim") {
    if (options.clock == "sim") resolve_clock("sim", kind);  // throws (run_command resolved the clock already)
    if (speed != 1.0) throw InputError("--device " + kind + " runs in real time: --speed must be 1");
    if (!options.resume_dir.empty())
      throw InputError("--resume continues a session on the simulated arm; it cannot go with --device " + kind);
  }
  if (kind == "lcm" || telemetry_) session_id_ = LcmDevice::random_session_id();
  device_ = open_device(device_parameters_, config, seed, options.rt, session_id_,
                        std::filesystem::path(options.config_path).parent_path());
  if (options.clock == "lockstep")
    device_->lcm_device()->set_lockstep(config.lcm.lockstep_timeout_s);  // before the engine
}

RunIo::~RunIo() { stop(); }

Device& RunIo::device() { return device_->device(); }

SimulatedArm* RunIo::simulated_arm() { return device_->simulated_arm(); }
SimulatedArmChain* RunIo::simulated_arm_chain() { return device_->simulated_arm_chain(); }

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
  if (options_.lcm_log)
    log_path_ = !options_.lcm_log_file.empty() ? options_.lcm_log_file : free_log_name(session_directory);
  if (!log_path_.empty()) {
    // The one safe writer: the log is written into its exclusive temporary (never through a name
    // planted in advance) and appears under its name, whole, when the run ends (finish_log()).
    log_file_ = std::make_unique<AtomicOutputFile>(log_path_, Replace::kRefused);
  }
  publisher_ = std::make_unique<TelemetryPublisher>(*tap_, session_id_, log_file_ ? log_file_->stream() : nullptr);
  publisher_io_ = std::make_unique<LcmIoThread>(options_.lcm_url, std::vector<LcmEndpoint*>{publisher_.get()});
  publisher_io_->start(RealtimeMode::kOff, 0);  // telemetry is not real-time
}

std::string RunIo::wait_for_rig(const std::atomic<bool>& stop, SimulatedClock* lockstep) {
  if (lockstep != nullptr) {  // no loop ticks the engine: these ticks send the commands that bind a rig
    const LcmDevice& rig = *device_->lcm_device();
    const double deadline_s = monotonic_s() + config_.lcm.connect_timeout_s;
    while (!rig.connected() && !stop.load(std::memory_order_relaxed) && monotonic_s() < deadline_s) lockstep->step(1);
  }
  return device_->wait_until_served(config_.lcm.connect_timeout_s, stop);
}

void RunIo::post_trial(const IterationSummary& summary, const Eigen::VectorXd& correction_bar) {
  if (publisher_) publisher_->post_trial(summary, correction_bar, config_.timing.sample_s());
}

void RunIo::stop() {
  if (device_) device_->stop();
  if (publisher_io_) publisher_io_->stop();
}

std::string RunIo::finish_log() {
  stop();  // the publisher wrote its last event
  if (!log_file_) return log_error_;
  const std::unique_ptr<AtomicOutputFile> log = std::move(log_file_);
  try {
    log->commit();
  } catch (const InputError& error) {
    log_error_ = std::string("the LCM log is not written: ") + error.what();
  }
  return log_error_;
}

nlohmann::json RunIo::report() const {
  if (session_id_ == 0) return nullptr;
  nlohmann::json lcm = {{"session_id", session_id_}};
  if (!options_.lcm_url.empty()) lcm["url"] = options_.lcm_url;
  if (device_parameters_.kind == "lcm") lcm["rig"] = device_->report();
  if (publisher_) {
    const TelemetryPublisherStats s = publisher_->stats();
    lcm["telemetry"] = {{"ticks", s.ticks},   {"dropped_ticks", s.dropped_ticks}, {"events", s.events},
                        {"trials", s.trials}, {"log_events", s.log_events},       {"errors", s.errors}};
    if (!log_path_.empty())
      lcm["telemetry"]["log"] = log_error_.empty() ? nlohmann::json(log_path_) : nlohmann::json(nullptr);
    if (!log_error_.empty()) lcm["telemetry"]["log_error"] = log_error_;
  }
  return lcm;
}

const LcmDevice* RunIo::lcm_device() const {
  return device_ ? dynamic_cast<const LcmDevice*>(&device_->device()) : nullptr;
}

std::string RunIo::explain_fault(FaultCode code) const {
  // The device named the fault foreign-sender (LcmDevice::explain_silence): its whole diagnosis.
  const LcmDevice* lcm_device_ = lcm_device();
  if (!lcm_device_ || code != FaultCode::kForeignSender) return "";
  const LcmDeviceStats s = lcm_device_->stats();
  if (s.commands_not_ours == 0 && s.states.unauthenticated == 0) return "";
  return lcm_device_->diagnosis();
}

std::string RunIo::warning() const {
  if (const LcmDevice* lcm_device_ = lcm_device()) {
    if (std::string why = lcm_device_->diagnosis(); !why.empty()) return why;
  }
  if (!publisher_) return "";
  const TelemetryPublisherStats s = publisher_->stats();
  if (s.dropped_ticks == 0 && s.errors == 0) return "";
  return "telemetry: " + std::to_string(s.dropped_ticks) + " ticks dropped, " + std::to_string(s.errors) +
         " publish or log errors";
}

}  // namespace bellows
