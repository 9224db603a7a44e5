// A device that loses readings and reports faults of its own, around any in-process arm: for the
// engine's ride-through and its device faults (tests only). During a gap read_sensors() returns the
// last reading again (the Device contract's "no reading this tick"); report() queues a DeviceFault
// for the next take_fault().
#pragma once

#include <utility>
#include <vector>

#include "engine/control/device.hpp"

namespace bellows::testing {

class GappyDevice final : public Device {
 public:
  /// `own_time`: a rig whose time passes on its own (as a remote one): a missed deadline is no warning.
  explicit GappyDevice(Device& arm, bool own_time = false) : arm_(arm), own_time_(own_time) {}

  /// Readings of reads [from, from + count) (counted from the first read, 0-based) are missing.
  void lose_readings(long from, long count) { gaps_.emplace_back(from, from + count); }
  /// From read `from` on, `count` readings missing, then `fresh` present, repeated `times`.
  void lose_repeatedly(long from, long count, long fresh, int times) {
    for (int i = 0; i < times; ++i) lose_readings(from + i * (count + fresh), count);
  }
  void report(const DeviceFault& fault) {
    pending_ = fault;
    has_pending_ = true;
  }
  long reads() const { return reads_; }
  bool missing(long read) const {
    for (const auto& [from, to] : gaps_) {
      if (read >= from && read < to) return true;
    }
    return false;
  }

  SensorReading read_sensors() override {
    if (!missing(reads_++) || !has_last_) {
      last_ = arm_.read_sensors();
      has_last_ = true;
    }
    return last_;
  }
  void write_valves(const ValveCommand& command) override { arm_.write_valves(command); }
  void vent() override { arm_.vent(); }
  void advance(double dt_s) override { arm_.advance(dt_s); }
  bool time_follows_ticks() const override { return !own_time_ && arm_.time_follows_ticks(); }
  const char* name() const override { return "gappy"; }
  bool take_fault(DeviceFault& fault) override {
    if (!has_pending_) return false;
    fault = pending_;
    has_pending_ = false;
    return true;
  }

 private:
  Device& arm_;
  std::vector<std::pair<long, long>> gaps_;
  long reads_ = 0;
  SensorReading last_{};
  bool has_last_ = false;
  DeviceFault pending_{};
  bool has_pending_ = false;
  bool own_time_ = false;
};

}  // namespace bellows::testing
