// Telemetry of an arm with several joints over LCM (issue 14): the publisher sends telemetry_joints_t
// (every joint's angle, set point, chambers, input, chamber set points and valves, and the joint a
// fault fired on) for arm2 and arm3, and telemetry_t, byte for byte as before, for one joint.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "bridge/telemetry_publisher.hpp"
#include "devices/lcm_channels.hpp"
#include "devices/simulated_arm.hpp"
#include "devices/simulated_arm_chain.hpp"
#include "engine/rt/engine_core.hpp"
#include "engine/rt/engine_driver.hpp"
#include "engine/model/pneumatic_arm_chain_parameters.hpp"
#include "tests/lcm_bench.hpp"

namespace bellows {
namespace {

using testing::BusRecorder;
using testing::decode;
using testing::pump;
using testing::Recorded;

/// An engine on `device` running `trajectory` for a second with a small correction, then faulted by
/// a guard or the operator; every tick goes through `tap`.
struct TelemetryBench {
  TelemetryBench(Device& device, const SafetyParameters& safety, const Trajectory& path)
      : core(device, config.controller, config.timing, safety),
        tap(core.add_telemetry_tap(1 << 14)),
        clock(core, device),
        trajectory(path) {}

  /// Arms, runs one second of a trial, stops (`stop`) or lets the trial run into a guard.
  void run(bool stop) {
    EXPECT_TRUE(core.send(EngineCommand::select_trajectory(trajectory)));
    EXPECT_TRUE(core.send(EngineCommand::of(CommandKind::kArm)));
    clock.step(100);
    record.prepare(trajectory.learning_samples(), config.timing.ticks_per_sample, trajectory.joints());
    correction = Eigen::MatrixXd::Constant(trajectory.learning_samples(), trajectory.joints(), 0.02);
    EXPECT_TRUE(core.send(EngineCommand::start_trial(trajectory, correction, record, 0, 1)));
    clock.step(std::lround((stop ? 1.0 : 8.0) / config.timing.tick_s));
    if (stop) core.request_emergency_stop();
    clock.step(3);
    EXPECT_EQ(core.state(), EngineState::kFault);
  }

  /// Everything the publisher sends for the ticks so far, on memq://.
  std::vector<Recorded> published() {
    TelemetryPublisher publisher(tap, 7, nullptr);
    lcm::LCM bus("memq://");
    BusRecorder recorder(kTelemetryChannel);
    recorder.attach(bus);
    publisher.service(&bus, 1.0);
    publisher.finish(&bus, 1.1);
    pump(bus);
    return recorder.messages();
  }

  Configuration config;
  EngineCore core;
  TelemetryRing& tap;
  SimulatedClock clock;
  Trajectory trajectory;
  TrialRecord record;
  Eigen::MatrixXd correction;
};

/// Every published tick against the engine's black box (its last ticks up to the fault).
class JointTelemetry : public ::testing::TestWithParam<std::pair<const char*, const char*>> {};

TEST_P(JointTelemetry, EveryTickCarriesEveryJoint) {
  const auto [preset, trajectory_name] = GetParam();
  Configuration config;
  config.arm.preset = preset;
  SimulatedArmChain arm(pneumatic_chain_of(config.plant, config.arm), 2);
  const Trajectory trajectory = library_trajectory(trajectory_name, config.timing.sample_s());
  TelemetryBench bench(arm, config.safety, trajectory);
  bench.run(true);
  const std::vector<TickRecord> box = bench.core.black_box().copy_frozen();  // the last ticks, to compare
  const std::vector<Recorded> messages = bench.published();
  ASSERT_EQ(messages.size(), bench.core.ticks()) << "one message per tick";
  const int joints = trajectory.joints();
  std::size_t compared = 0;
  for (std::size_t i = 0; i < messages.size(); ++i) {
    const telemetry_joints_t t = decode<telemetry_joints_t>(messages[i]);
    ASSERT_EQ(t.tick, static_cast<std::int64_t>(i));
    ASSERT_EQ(t.joint_count, joints);
    EXPECT_EQ(t.session_id, 7);
    const auto first_boxed = static_cast<std::size_t>(box.front().tick);  // the box froze on the fault tick
    if (i < first_boxed || i >= first_boxed + box.size()) continue;
    const TickRecord& tick = box[i - first_boxed];
    ASSERT_EQ(static_cast<std::uint64_t>(t.tick), tick.tick);
    EXPECT_EQ(t.fault, fault_code(tick.fault));
    EXPECT_EQ(t.supply_bar, tick.reading.supply_bar);
    for (int j = 0; j < kMaxJoints; ++j) {
      const auto ji = static_cast<std::size_t>(j);
      SCOPED_TRACE("tick " + std::to_string(i) + ", joint " + std::to_string(j + 1));
      if (j >= joints) {  // rows beyond the arm's joints are zero
        EXPECT_EQ(t.angle_rad[j], 0.0);
        EXPECT_EQ(t.outlet_duty[j][1], 0.0);
        continue;
      }
      EXPECT_EQ(t.angle_rad[j], tick.reading.joint[ji].angle_rad);
      EXPECT_EQ(t.desired_angle_rad[j], tick.joint(j).desired_rad);
      EXPECT_EQ(t.chamber_bar[j][1], tick.reading.joint[ji].chamber_bar[1]);
      EXPECT_EQ(t.u_total_bar[j], tick.joint(j).u_total_bar);
      EXPECT_EQ(t.setpoint_bar[j][0], tick.joint(j).setpoints.a_bar);
      EXPECT_EQ(t.saturation[j], tick.joint(j).setpoints.saturation_sign);
      EXPECT_EQ(t.inlet_duty[j][0], tick.valves.joint[ji].inlet_duty[0]);
      EXPECT_EQ(t.outlet_duty[j][1], tick.valves.joint[ji].outlet_duty[1]);
    }
    ++compared;
  }
  EXPECT_EQ(compared, box.size());
  // The last joint moves on its own: its values are not joint 1's.
  const telemetry_joints_t running = decode<telemetry_joints_t>(messages[box.front().tick + box.size() / 2]);
  EXPECT_EQ(running.state, std::int8_t{telemetry_t::STATE_RUNNING});
  EXPECT_NE(running.u_total_bar[joints - 1], running.u_total_bar[0]);
  EXPECT_NE(running.angle_rad[joints - 1], running.angle_rad[0]);
  const telemetry_joints_t last = decode<telemetry_joints_t>(messages.back());
  EXPECT_EQ(last.fault, fault_code(FaultCode::kEmergencyStop));
  EXPECT_EQ(last.fault_joint, 0) << "an operator's stop is no joint's";
}

INSTANTIATE_TEST_SUITE_P(Arms, JointTelemetry,
                         ::testing::Values(std::pair{"arm2", "paper2"}, std::pair{"arm3", "paper3"}),
                         [](const auto& arm) { return std::string(arm.param.first); });

TEST(JointTelemetryFault, NamesTheJointTheGuardFiredOn) {
  Configuration config;
  config.arm.preset = "arm2";
  SimulatedArmChain arm(pneumatic_chain_of(config.plant, config.arm), 2);
  SafetyParameters safety = config.safety;
  safety.joint_angle_limit_deg[1] = 25.0;  // paper2's elbow goes to +-30 deg
  TelemetryBench bench(arm, safety, library_trajectory("paper2", config.timing.sample_s()));
  bench.run(false);
  const std::vector<Recorded> messages = bench.published();
  ASSERT_FALSE(messages.empty());
  std::size_t fault_tick = 0;  // the first tick with the fault: the elbow beyond its limit there
  while (fault_tick < messages.size() && decode<telemetry_joints_t>(messages[fault_tick]).fault == 0) ++fault_tick;
  ASSERT_LT(fault_tick, messages.size());
  const telemetry_joints_t first = decode<telemetry_joints_t>(messages[fault_tick]);
  EXPECT_EQ(first.fault, fault_code(FaultCode::kAngleLimit));
  EXPECT_EQ(first.fault_joint, 2);
  EXPECT_GT(std::abs(first.angle_rad[1]), 25.0 * std::numbers::pi / 180.0);
  EXPECT_EQ(decode<telemetry_joints_t>(messages[fault_tick - 1]).fault_joint, 0) << "before the fault: no joint";
  const telemetry_joints_t last = decode<telemetry_joints_t>(messages.back());
  EXPECT_EQ(last.fault_joint, 2) << "latched with the fault";
}

TEST(JointTelemetryFault, OneJointStillSpeaksTelemetryT) {
  Configuration config;
  SimulatedArm arm(config.plant, 2);
  TelemetryBench bench(arm, config.safety, library_trajectory("paper", config.timing.sample_s()));
  bench.run(true);
  const std::vector<Recorded> messages = bench.published();
  ASSERT_EQ(messages.size(), bench.core.ticks());
  for (const Recorded& m : messages) {
    telemetry_t t{};
    ASSERT_EQ(decode_checked(m.bytes.data(), m.bytes.size(), t), DecodeStatus::kOk);
    EXPECT_EQ(m.bytes.size(), static_cast<std::size_t>(telemetry_t{}.getEncodedSize()));
  }
  const telemetry_t last = decode<telemetry_t>(messages.back());
  TickRecord tick;
  ASSERT_TRUE(bench.core.read_snapshot(tick));
  EXPECT_EQ(last.angle_rad, tick.reading.joint[0].angle_rad);
  EXPECT_EQ(last.u_total_bar, tick.joint(0).u_total_bar);
  // And the joint message is refused as another type by a reader of telemetry_t.
  std::vector<std::uint8_t> bytes;
  const std::size_t size = encode_into(telemetry_joints_t{}, bytes);
  telemetry_t out{};
  EXPECT_EQ(decode_checked(bytes.data(), size, out), DecodeStatus::kWrongType);
}

}  // namespace
}  // namespace bellows
