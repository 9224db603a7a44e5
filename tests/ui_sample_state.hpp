// A console state built by hand for the screen tests: what render() is given.
#pragma once

#include <memory>
#include <numbers>
#include <string>
#include <vector>

#include "engine/trial/trajectory.hpp"
#include "ui/console_state.hpp"
#include "tests/test_support.hpp"

namespace bellows::testing {

using ui::ConsoleState;
using ui::Experiment;
using ui::LogSource;
using ui::Trial;

inline constexpr double kDeg = std::numbers::pi / 180.0;

inline std::string all(const std::vector<std::string>& lines) {
  std::string out;
  for (const auto& l : lines) out += l + "\n";
  return out;
}

// A state with `trials` trials on the paper trajectory: trial i tracks with an error that shrinks
// as 1/(i+1), its correction is a constant 0.01 i bar, its RMS 10/(i+1) deg.
inline ConsoleState sample_state(int trials, bool unicode) {
  ConsoleState s;
  s.width = 120;
  s.height = 40;
  s.unicode = unicode;
  s.engine_state = EngineState::kArmed;
  s.device = {"sim", true, "ok"};
  s.loop.ticks = 123456;
  s.loop.p50_us = 24;
  s.loop.p99_us = 51;
  s.loop.max_us = 80;
  s.loop.rt = "fifo";
  s.law_name = "noilc";
  s.law_ready = true;
  auto trajectory = std::make_shared<const Trajectory>(library_trajectory("paper", 0.02));
  s.experiment = Experiment::start(trajectory);
  const int n = trajectory->learning_samples();
  for (int i = 0; i < trials; ++i) {
    Trial t;
    t.correction_bar = Eigen::VectorXd::Constant(n, 0.01 * i);
    t.record.prepare(n, 4);
    TrialSamples& r = t.record.joint_samples(0);
    for (int k = 0; k <= n; ++k) {
      t.record.sample_time_s(k) = k * 0.02;
      r.setpoint_rad(k) = trajectory->joint(0)(k);
      r.angle_rad(k) = trajectory->joint(0)(k) * (1.0 - 0.5 / (i + 1));
      r.error_rad(k) = r.setpoint_rad(k) - r.angle_rad(k);
      r.u_pid_bar(k) = 0.001 * k;
      r.u_ilc_bar(k) = 0.01 * i;
      r.pressure_a_bar(k) = 1.1;
      r.pressure_b_bar(k) = 1.05;
    }
    t.record.complete = true;
    t.summary.rms_deg = 10.0 / (i + 1);
    t.origin = i == 0 ? "feedback only" : "learned from " + std::to_string(i - 1);
    s.experiment.add_trial(std::move(t));
  }
  s.live_valid = true;
  s.live.state = EngineState::kArmed;  // the latest tick, like the engine it came from
  s.live.reading.joint[0].angle_rad = 12.5 * kDeg;
  s.live.joint(0).desired_rad = 12.0 * kDeg;
  s.live.reading.joint[0].chamber_bar = {1.234, 1.1};
  s.live.reading.supply_bar = 3.0;
  s.live.valves.joint[0].inlet_duty = {0.5, 0.0};
  s.live.valves.joint[0].outlet_duty = {0.0, 0.25};
  s.log.add({"12:00:00", 0.0, LogSource::kOperator, "console started", false, false, "", 0, {}});
  s.log.add({"12:00:01", 0.5, LogSource::kEngine, "SAFE -> ARMED (arm)", false, false, "", 0, {}});
  s.log.add({"12:00:02", 1.0, LogSource::kEngine, "ARMED -> RUNNING (start trial)", false, true, "", 0, {}});
  s.status = "hello operator";
  return s;
}

}  // namespace bellows::testing
