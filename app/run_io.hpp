// What `bellows run` drives and who watches it: the simulated arm in-process (`--device sim`) or a
// rig over LCM (`--device lcm`), and, with `--lcm URL` or `--lcm-log`, the telemetry publisher.
// Owns the LCM I/O threads and stops them in the right order.
#pragma once

#include <atomic>
#include <cstdint>
#include <filesystem>
#include <memory>
#include <string>

#include <nlohmann/json.hpp>

#include "app/run_command.hpp"
#include "bridge/telemetry_publisher.hpp"
#include "devices/lcm_device.hpp"
#include "devices/simulated_arm.hpp"
#include "devices/simulated_arm_chain.hpp"
#include "engine/config/configuration.hpp"
#include "engine/rt/engine_core.hpp"
#include "engine/rt/engine_driver.hpp"
#include "engine/operator/learning_session.hpp"

namespace bellows {

class OpenedDevice;
class AtomicOutputFile;

/// Received-message counters as a JSON object ({"accepted", "ignored": {by reason}}).
nlohmann::json receive_counts_json(const ReceiveCounts& counts);

class RunIo {
 public:
  /// Checks the options against each other and opens the device (app/device_factory). Throws
  /// InputError for a combination that makes no sense or a bus that cannot be opened.
  RunIo(const RunOptions& options, double speed, std::uint64_t seed, const Configuration& config);
  ~RunIo();
  RunIo(const RunIo&) = delete;
  RunIo& operator=(const RunIo&) = delete;

  /// The device the engine drives.
  Device& device();
  /// The simulated arm, or null for a rig.
  SimulatedArm* simulated_arm();
  /// The simulated arm of several joints ([arm] chain on sim), or null.
  SimulatedArmChain* simulated_arm_chain();
  /// The device as opened (its session record, its name).
  const OpenedDevice& opened() const { return *device_; }
  const DeviceParameters& device_parameters() const { return device_parameters_; }

  /// Adds the telemetry tap, if telemetry is asked for. After the EngineCore is built, before any
  /// tick and before simulated_clock().
  void add_telemetry_tap(EngineCore& core);
  /// The simulated clock for `--clock sim` and `--clock lockstep`. With telemetry it waits for the publisher whenever
  /// the tap is full, so that a log holds every tick (simulated time has no deadline to miss).
  std::unique_ptr<SimulatedClock> simulated_clock(EngineCore& core);
  /// Starts the publisher. `session_directory` (empty without a session) receives the LCM log when
  /// --lcm-log names no file. Before the first tick.
  void start_telemetry(const std::filesystem::path& session_directory);
  /// With a rig (lcm, t7): waits (the engine loop running) until a rig serves this session. Returns
  /// an empty string when it does, else why not; gives up early when `stop` is set.
  /// `lockstep` (`--clock lockstep`): the simulated clock this thread ticks until a rig serves the
  /// engine (nothing else sends its commands); null on the wall clock.
  std::string wait_for_rig(const std::atomic<bool>& stop, SimulatedClock* lockstep = nullptr);
  /// Operator thread, after each completed trial.
  void post_trial(const IterationSummary& summary, const Eigen::VectorXd& correction_bar);
  /// After the engine loop stopped: the device's last vent on the bus, the rest of the telemetry,
  /// the log closed.
  void stop();
  /// Instead of stop() when a run ended (completed or faulted): stops, then publishes the LCM log
  /// under its name (fsync, rename, fsync of the folder). Returns "" or "the LCM log is not
  /// written: ..." (a full disk, a file of that name that appeared meanwhile), also in report().
  /// A run that never gets here (an exception, a kill) leaves no log under the name.
  std::string finish_log();

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
  /// A better account of an engine fault than its name, or "": a sensor-stale fault while another
  /// sender commands the rig (or forges its states) is that sender's doing.
  std::string explain_fault(FaultCode code) const;
  /// The LCM device when the run drives a rig over LCM, else null.
  const LcmDevice* lcm_device() const;

 private:
  const RunOptions& options_;
  Configuration config_;
  bool telemetry_ = false;
  DeviceParameters device_parameters_;
  std::unique_ptr<OpenedDevice> device_;
  TelemetryRing* tap_ = nullptr;
  std::string log_path_;
  std::string log_error_;
  std::unique_ptr<AtomicOutputFile> log_file_;  // declared before the publisher, which writes into it
  std::unique_ptr<TelemetryPublisher> publisher_;
  std::unique_ptr<LcmIoThread> publisher_io_;
  std::int64_t session_id_ = 0;
};

}  // namespace bellows
