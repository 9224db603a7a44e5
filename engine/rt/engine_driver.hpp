// How an operator (headless run, console, tests) lets engine time pass, whatever the clock:
// SimulatedClock ticks the engine on the caller's thread as fast as possible (deterministic);
// RealtimeLoop ticks it on its own thread on wall-clock deadlines, and await() just waits a little.
#pragma once

#include <chrono>
#include <thread>

#include "engine/rt/engine_core.hpp"

namespace bellows {

class EngineDriver {
 public:
  virtual ~EngineDriver() = default;
  virtual EngineCore& core() = 0;
  /// Let a little engine time pass (at least one tick on a simulated clock).
  virtual void await() = 0;
  /// Whether time is simulated (deterministic, as fast as possible).
  virtual bool simulated() const = 0;
};

/// Ticks the engine on the calling thread: tick, then advance the device by one tick.
class SimulatedClock final : public EngineDriver {
 public:
  SimulatedClock(EngineCore& core, Device& device) : core_(core), device_(device) {}

  void step(long ticks = 1) {
    const double tick_s = core_.timing().tick_s;
    for (long i = 0; i < ticks; ++i) {
      const double now = static_cast<double>(ticks_) * tick_s;
      core_.tick(now, now, 0);
      device_.advance(tick_s);
      ++ticks_;
    }
  }
  double now_s() const { return static_cast<double>(ticks_) * core_.timing().tick_s; }
  long long ticks() const { return ticks_; }
  void set_ticks(long long ticks) { ticks_ = ticks; }

  /// Paces await() by a telemetry ring: waits while it is full, so that its consumer (a publisher
  /// writing a log) sees every tick. Simulated time has no deadline to miss.
  void pace_by(const TelemetryRing* tap) { pace_ = tap; }

  EngineCore& core() override { return core_; }
  void await() override {
    while (pace_ != nullptr && pace_->write_available() == 0)
      std::this_thread::sleep_for(std::chrono::microseconds(200));
    step(1);
  }
  bool simulated() const override { return true; }

 private:
  EngineCore& core_;
  Device& device_;
  long long ticks_ = 0;
  const TelemetryRing* pace_ = nullptr;
};

}  // namespace bellows
