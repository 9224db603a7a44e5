// The engine on its own thread (wall clock): a trial end to end, snapshots and telemetry read from
// another thread, the heartbeat guard, and stop() venting. Run under ThreadSanitizer in CI.
#include <gtest/gtest.h>

#include <chrono>
#include <thread>

#include "devices/simulated_arm.hpp"
#include "engine/config/configuration.hpp"
#include "engine/operator/learning_session.hpp"
#include "engine/learning/noilc_dense.hpp"
#include "engine/base/errors.hpp"
#include "engine/rt/realtime_loop.hpp"

namespace bellows {
namespace {

Trajectory short_move() {
  return trajectory_from_moves("short", 0.0, {TrapezoidalMove{0.2, 0.0, 20.0, 0.3, 4000.0}}, 1.0, 0.02);
}

TEST(RealtimeLoop, RunsATrialOnItsOwnThreadAndVentsOnStop) {
  Configuration c;
  c.timing.settle_s = 0.2;
  SimulatedArm arm(c.plant, 1);
  EngineCore core(arm, c.controller, c.timing, c.safety);
  TelemetryRing& tap = core.add_telemetry_tap(4096);
  RealtimeLoop loop(core, arm, 10.0);  // ten times faster than real time
  loop.start(RealtimeMode::kOff);
  const Trajectory trajectory = short_move();
  NormOptimalDense law(discretize_arm_model(c.model, 0.02), c.ilc, trajectory.learning_samples());
  LearningSession session(loop, law, trajectory, c.timing, c.controller);

  std::atomic<bool> done{false};
  std::size_t telemetry_seen = 0;
  std::thread consumer([&] {  // a UI-like reader: snapshots and the telemetry ring
    TickRecord record;
    while (!done.load()) {
      core.read_snapshot(record);
      telemetry_seen += tap.pop(&record, 1);
      std::this_thread::sleep_for(std::chrono::microseconds(200));
    }
    TickRecord drain;
    while (tap.pop(drain)) ++telemetry_seen;
  });
  const IterationSummary first = session.run_trial();
  session.learn();
  const IterationSummary second = session.run_trial();
  done.store(true);
  consumer.join();
  loop.stop();

  EXPECT_GT(first.rms_deg, 0.5);
  EXPECT_LT(second.rms_deg, first.rms_deg);
  const LatencySummary latency = loop.latency();
  EXPECT_GE(latency.ticks, 2u * (40u + 200u));  // two trials: settle 0.2 s + 1 s, at 200 Hz
  EXPECT_GE(latency.max_us, latency.p99_us);
  EXPECT_GE(latency.p99_us, latency.p50_us);
  EXPECT_GT(telemetry_seen, 400u);
  const SimulatedArm::State s = arm.state();
  EXPECT_EQ(s.command.inlet_duty[0], 0.0);
  EXPECT_EQ(s.command.outlet_duty[0], 1.0);
}

TEST(RealtimeLoop, HungConsoleTripsTheHeartbeatGuard) {
  Configuration c;
  c.safety.heartbeat_timeout_s = 0.2;
  c.safety.missed_deadline_streak = 1000000;  // a loaded test machine must not trip this guard here
  SimulatedArm arm(c.plant, 1);
  EngineCore core(arm, c.controller, c.timing, c.safety);
  core.monitor_heartbeat(true);
  RealtimeLoop loop(core, arm, 1.0);
  loop.start(RealtimeMode::kOff);
  EXPECT_TRUE(core.send(EngineCommand::of(CommandKind::kArm)));
  const auto start = std::chrono::steady_clock::now();
  const EngineCommand heartbeat = EngineCommand::of(CommandKind::kHeartbeat);
  while (std::chrono::steady_clock::now() - start < std::chrono::milliseconds(500)) {  // a live console
    EXPECT_TRUE(core.send(heartbeat));
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  EXPECT_EQ(core.state(), EngineState::kArmed);
  const auto hung = std::chrono::steady_clock::now();  // the console hangs
  while (core.state() != EngineState::kFault && std::chrono::steady_clock::now() - hung < std::chrono::seconds(5)) {
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  EXPECT_EQ(core.fault(), FaultCode::kHeartbeatLost);
  loop.stop();
}

TEST(RealtimeLoop, EnforceRefusesClearlyWhenRealTimeIsNotAllowed) {
  Configuration c;
  SimulatedArm arm(c.plant, 1);
  EngineCore core(arm, c.controller, c.timing, c.safety);
  RealtimeLoop loop(core, arm, 1.0);
  try {
    loop.start(RealtimeMode::kEnforce);
    EXPECT_TRUE(loop.rt_granted());  // allowed here (root): then it must really be FIFO
    EXPECT_EQ(loop.rt_description(), "fifo");
    loop.stop();
  } catch (const EnvironmentError& e) {  // the environment refused: exit status 4
    EXPECT_NE(std::string(e.what()).find("--rt enforce"), std::string::npos) << e.what();
    EXPECT_EQ(e.exit_status(), kExitEnvironment);
  }
}

}  // namespace
}  // namespace bellows
