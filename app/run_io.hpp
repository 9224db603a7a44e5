// What `bellows run` drives and who watches it: the simulated arm in-process (`--device sim`) or a
// rig over LCM (`--device lcm`), and, with `--lcm URL` or `--lcm-log FILE`, the telemetry
// publisher. Owns the LCM I/O threads and stops them in the right order.
#pragma once

#include <atomic>
#include <cstdint>
#include <memory>
#include <string>

#include <nlohmann/json.hpp>

#include "bridge/telemetry_publisher.hpp"
#include "devices/lcm_device.hpp"
#include "devices/simulated_arm.hpp"
#include "engine/configuration.hpp"
#include "engine/engine_core.hpp"
#include "engine/learning_session.hpp"

namespace bellows {

struct RunIoOptions {
  std::string device = "sim";  // sim | lcm
  std::string lcm_url;         // --lcm: the bus (telemetry; the rig's bus with --device lcm)
  std::string lcm_log;         // --lcm-log: an LCM event log of the telemetry
  std::string clock = "sim";
  double speed = 1.0;
  std::uint64_t seed = 1;
  RealtimeMode rt = RealtimeMode::kTry;
};

/// Received-message counters as a JSON object ({"accepted", "ignored": {by reason}}).
nlohmann::json receive_counts_json(const ReceiveCounts& counts);

class RunIo {
 public:
  /// Checks the options against each other and opens the rig's bus (`--device lcm`). Throws
  /// InputError for a combination that makes no sense or a bus that cannot be opened.
  RunIo(const RunIoOptions& options, const Configuration& config);
  ~RunIo();

  Device& device();
  bool lcm_device() const { return lcm_device_ != nullptr; }

  /// The simulated clock for `--clock sim`. With telemetry it waits for the publisher whenever the
  /// tap is full, so that a log holds every tick (simulated time has no deadline to miss).
  std::unique_ptr<SimulatedClock> simulated_clock(EngineCore& core);
  /// The in-process simulated arm, or null when the device is a rig over LCM.
  SimulatedArm* simulated_arm();
  /// Adds the telemetry tap and starts the publisher, if asked for. Before the engine loop starts.
  void start_telemetry(EngineCore& core);
  /// With --device lcm: waits (the engine loop running) until a rig serves this session. Returns
  /// an empty string when it does, else why not; gives up early when `stop` is set.
  std::string wait_for_rig(const std::atomic<bool>& stop);
  /// Operator thread, after each completed trial.
  void post_trial(const IterationSummary& summary, const Eigen::VectorXd& correction_bar);
  /// After the engine loop stopped: the device's last vent on the bus, the rest of the telemetry,
  /// the log closed.
  void stop();

  /// Stops the I/O threads when it goes out of scope: declare it after the EngineCore whose
  /// telemetry tap the publisher drains, so that an exception never leaves it draining a freed ring.
  class StopOnExit {
   public:
    explicit StopOnExit(RunIo& io) : io_(io) {}
    ~StopOnExit() { io_.stop(); }
    StopOnExit(const StopOnExit&) = delete;
    StopOnExit& operator=(const StopOnExit&) = delete;

   private:
    RunIo& io_;
  };

  /// The "lcm" object of the JSON report (null when no LCM was used); a warning line or "".
  nlohmann::json report() const;
  std::string warning() const;

 private:
  RunIoOptions options_;
  Configuration config_;
  std::unique_ptr<SimulatedArm> arm_;
  std::unique_ptr<LcmDevice> lcm_device_;
  std::unique_ptr<LcmIoThread> device_io_;
  std::unique_ptr<TelemetryPublisher> publisher_;
  std::unique_ptr<LcmIoThread> publisher_io_;
  TelemetryRing* tap_ = nullptr;
  std::int64_t session_id_ = 0;
};

}  // namespace bellows
