// `bellows io-sim --config arm2.toml` as its own process over UDP multicast, inside a private network
// namespace this test makes for itself (nothing leaves it; skipped, saying why, where none can be
// made): it serves the two-joint simulated arm in the joint messages; an LCM device of two joints
// binds to it and reads both joints; one of one joint (today's messages) refuses it in one line; and
// `bellows run --device lcm` with the same [arm] learns it as the in-process arm does.
#include <gtest/gtest.h>

#include <signal.h>

#include <iostream>

#include <nlohmann/json.hpp>

#include "devices/lcm_channels.hpp"
#include "devices/lcm_device.hpp"
#include "devices/lcm_io_messages.hpp"
#include "tests/lcm_test_support.hpp"
#include "tests/process_runner.hpp"

namespace bellows {
namespace {

using testing::Child;

/// Vents (what an engine in SAFE sends every tick) until `done` or `timeout_s`.
bool vent_until(LcmDevice& device, const std::function<bool()>& done, double timeout_s) {
  return testing::eventually(
      [&] {
        device.vent();
        return done();
      },
      timeout_s);
}

TEST(LcmJointProcesses, IoSimServesArm2InTheJointMessagesAndAnEngineOfOneJointRefusesItInOneLine) {
  const std::string why_not = testing::enter_private_network_namespace();
  if (!why_not.empty()) GTEST_SKIP() << "no private network namespace: " << why_not;
  const auto dir = testing::make_temp_dir("bellows-lcm-joints");
  const std::string config = testing::write_file(dir, "arm2.toml", "[arm]\npreset = \"arm2\"\n").string();
  Child rig({testing::kBellows, "io-sim", "--json", "--rt", "off", "--config", config}, dir / "rig.out",
            dir / "rig.err");
  ASSERT_TRUE(rig.started());

  LcmDevice one_joint(LcmDevice::random_session_id());  // an engine of today's single-joint arm
  testing::BusRecorder states(kIoStateChannel);
  {
    LcmIoThread bus(kDefaultLcmUrl, {&one_joint, &states});
    bus.start(RealtimeMode::kOff, 0);
    EXPECT_TRUE(vent_until(
        one_joint, [&] { return one_joint.stats().states.other_joints >= 20; }, 20.0))
        << rig.err();
    bus.stop();
  }
  EXPECT_FALSE(one_joint.connected());
  EXPECT_EQ(one_joint.stats().states.accepted, 0u);
  EXPECT_EQ(
      one_joint.diagnosis().rfind(
          "a rig on this bus serves an arm of 2 joints but this arm has one joint (io_state_t / io_command_t)", 0),
      0u)
      << one_joint.diagnosis();
  ASSERT_FALSE(states.messages().empty());
  for (const testing::Recorded& r : states.messages()) {
    io_joints_state_t s{};
    ASSERT_EQ(decode_checked(r.bytes.data(), r.bytes.size(), s), DecodeStatus::kOk)
        << "io-sim speaks the joint messages";
    EXPECT_EQ(s.joint_count, 2);
  }

  LcmDevice two_joints(LcmDevice::random_session_id(), LcmKey{}, 0.05, 2);
  {
    LcmIoThread bus(kDefaultLcmUrl, {&two_joints});
    bus.start(RealtimeMode::kOff, 0);
    EXPECT_TRUE(vent_until(
        two_joints, [&] { return two_joints.connected(); }, 20.0))
        << rig.err();
    const SensorReading reading = two_joints.read_sensors();
    EXPECT_EQ(reading.joint_count, 2);
    EXPECT_NEAR(reading.supply_bar, 3.0, 0.05);
    for (int j = 0; j < 2; ++j)
      EXPECT_NEAR(reading.joint[static_cast<std::size_t>(j)].chamber_bar[0], 1.013, 0.05) << "vented";
    bus.stop();
  }
  EXPECT_EQ(two_joints.stats().states.other_joints, 0u);
  EXPECT_EQ(two_joints.diagnosis(), "");

  // `bellows run --device lcm` of one joint against it: refused in one line, exit 4 (rig unavailable).
  const std::string quick = testing::write_file(dir, "one.toml", "[lcm]\nconnect_timeout_s = 1\n").string();
  Child run({testing::kBellows, "run", "--no-save", "--device", "lcm", "--clock", "wall", "--iterations", "1", "--json",
             "--config", quick},
            dir / "run.out", dir / "run.err");
  const auto run_status = run.wait(60.0);
  ASSERT_TRUE(run_status.has_value()) << "bellows run did not give up";
  EXPECT_EQ(*run_status, 4) << run.err();
  EXPECT_EQ(nlohmann::json::parse(run.out())["fault"]["name"], "rig-unavailable");
  EXPECT_NE(run.err().find("a rig on this bus serves an arm of 2 joints but this arm has one joint"), std::string::npos)
      << run.err();

  rig.signal(SIGTERM);
  ASSERT_TRUE(rig.wait(30.0).has_value()) << "io-sim did not stop on SIGTERM";
  EXPECT_NE(rig.err().find("io-sim: serving the simulated arm 'arm2' of 2 joints on"), std::string::npos) << rig.err();
  const nlohmann::json report = nlohmann::json::parse(rig.out());
  EXPECT_EQ(report["joints"], 2);
  EXPECT_EQ(report["sessions_served"], 1);
  EXPECT_GT(report["commands"]["accepted"].get<int>(), 0);
  EXPECT_GT(report["not_addressed"].get<int>(), 0) << "the engine of one joint addressed no rig";
}

TEST(LcmJointProcesses, RunDrivesArm2OverLcmAndEveryJointTracksAsTheInProcessArm) {
  const std::string why_not = testing::enter_private_network_namespace();
  if (!why_not.empty()) GTEST_SKIP() << "no private network namespace: " << why_not;
  setenv("XDG_DATA_HOME", testing::make_temp_dir("bellows-lcm-joints-xdg").c_str(), 1);
  const auto dir = testing::make_temp_dir("bellows-lcm-joints-run");
  // Learning, not deadline keeping, is compared: in lockstep (io-sim --stepped, run --clock lockstep)
  // a loaded machine stalling either process changes none of the numbers; the free-running rig on the
  // wall clock has tests of its own.
  const std::string config = testing::write_file(dir, "arm2.toml", "[arm]\npreset = \"arm2\"\n").string();
  Child rig({testing::kBellows, "io-sim", "--stepped", "--seed", "5", "--config", config}, dir / "rig.out",
            dir / "rig.err");
  ASSERT_TRUE(rig.started());
  Child run({testing::kBellows, "run", "--no-save", "--device", "lcm", "--clock", "lockstep", "--iterations", "2",
             "--json", "--seed", "5", "--trajectory", "paper2", "--config", config},
            dir / "run.out", dir / "run.err");
  const auto run_status = run.wait(300.0);
  ASSERT_TRUE(run_status.has_value()) << "bellows run did not finish in 5 minutes";
  EXPECT_EQ(*run_status, 0) << run.err();
  rig.signal(SIGTERM);
  ASSERT_TRUE(rig.wait(30.0).has_value());
  const testing::ProcessResult local = testing::run_process(
      testing::kBellows + " run --no-save --iterations 2 --json --seed 5 --trajectory paper2 --config " + config);
  ASSERT_EQ(local.exit_code, 0) << local.err;
  const nlohmann::json remote = nlohmann::json::parse(run.out())["iterations"];
  const nlohmann::json in_process = nlohmann::json::parse(local.out)["iterations"];
  ASSERT_EQ(remote.size(), 3u);  // iteration 0 (feedback only), then two learned
  ASSERT_EQ(in_process.size(), remote.size());
  for (std::size_t i = 0; i < remote.size(); ++i) {
    ASSERT_EQ(remote[i]["joint_rms_deg"].size(), 2u);
    for (std::size_t j = 0; j < 2; ++j) {
      const double over_lcm = remote[i]["joint_rms_deg"][j].get<double>(),
                   local_rms = in_process[i]["joint_rms_deg"][j].get<double>();
      std::cout << "arm2/paper2 iteration " << i << ", joint " << j + 1 << ": " << over_lcm << " deg over LCM, "
                << local_rms << " deg in process\n";
      EXPECT_NEAR(over_lcm, local_rms, 0.01 * local_rms) << "iteration " << i << ", joint " << j + 1;
    }
  }
}

}  // namespace
}  // namespace bellows
