// Engine telemetry on LCM (`bellows run --lcm URL`) and in an LCM event log (`--lcm-log FILE`).
//
// Runs as an endpoint of its own, non-real-time LcmIoThread, fed by one engine telemetry tap (an
// SPSC ring the engine fills every tick): the loop never calls LCM, never writes files. Per tick
// it publishes a telemetry_t (one joint, as always) or a telemetry_joints_t (an arm of several
// joints: every joint's values, on the same channel); from consecutive ticks it derives engine events (state changes,
// faults, trials started and ended); the operator thread posts a trial summary after every
// completed trial. Every message published also goes into the log, written by LCM's own event-log
// writer (lcm_eventlog_write_event) in LCM's format, so lcm-logplayer replays it and any LCM tool
// reads it. The log's stream is the caller's (bellows run: the safe writer's temporary, published
// when the run ends, app/run_io). Log timestamps are the
// engine's time from the run's start (wall clock at the start + engine time), so a replay keeps
// the tick rate even when the publisher drains the ring in bursts.
#pragma once

#include <atomic>
#include <cstdio>
#include <cstdint>
#include <deque>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include <Eigen/Dense>
#include <lcm/eventlog.h>

#include "devices/lcm_codec.hpp"
#include "devices/lcm_io_thread.hpp"
#include "engine/rt/engine_core.hpp"
#include "engine/operator/learning_session.hpp"

namespace bellows {

struct TelemetryPublisherStats {
  std::uint64_t ticks = 0;          // telemetry_t published (and logged)
  std::uint64_t dropped_ticks = 0;  // ticks missing from the ring (it was full)
  std::uint64_t events = 0;
  std::uint64_t trials = 0;
  std::uint64_t log_events = 0;  // events written into the log
  std::uint64_t errors = 0;      // failed publishes or log writes
};

/// LCM's codes for engine states and faults (telemetry_t, engine_event_t).
std::int8_t state_code(EngineState state);
std::int8_t fault_code(FaultCode fault);

class TelemetryPublisher final : public LcmEndpoint {
 public:
  /// `log` null: no log. Else the stream the event log is written into (the caller's; it outlives
  /// the publisher's finish() and is flushed and closed by the caller).
  TelemetryPublisher(TelemetryRing& ring, std::int64_t session_id, std::FILE* log);
  ~TelemetryPublisher() override;

  /// Operator thread: a trial completed with `summary`, having applied `correction_bar`.
  void post_trial(const IterationSummary& summary, const Eigen::VectorXd& correction_bar, double sample_s);

  double service(lcm::LCM* bus, double now_s) override;
  void finish(lcm::LCM* bus, double now_s) override;

  /// Any thread.
  TelemetryPublisherStats stats() const;

 private:
  void drain(lcm::LCM* bus);
  void on_tick(lcm::LCM* bus, const TickRecord& tick);
  void publish_joints(lcm::LCM* bus, const TickRecord& tick, int joints);
  void emit_event(lcm::LCM* bus, const TickRecord& tick, std::int8_t kind, const std::string& text);
  template <typename Message>
  void emit(lcm::LCM* bus, const char* channel, const Message& message, std::atomic<std::uint64_t>& counter);

  TelemetryRing& ring_;
  const std::int64_t session_id_;
  lcm_eventlog_t log_{};  // LCM's writer state over the caller's stream (log_.f null: no log)
  std::int64_t log_epoch_us_ = 0;

  // I/O thread state.
  TickRecord previous_{};  // before the first tick: the engine's initial state
  bool have_previous_ = false;
  double latest_time_s_ = 0.0;
  telemetry_t telemetry_{};
  telemetry_joints_t joints_telemetry_{};
  engine_event_t event_{};
  std::vector<std::uint8_t> buffer_;

  std::mutex trials_mutex_;  // operator thread -> I/O thread; neither is real-time
  std::deque<trial_summary_t> trials_;

  std::atomic<std::uint64_t> ticks_{0}, dropped_ticks_{0}, events_{0}, trials_published_{0}, log_events_{0}, errors_{0};
};

}  // namespace bellows
