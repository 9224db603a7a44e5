// `bellows run` with an arm of several joints (issue 14) as a user runs it: `[arm] preset` chooses the
// simulated chain, the trajectory must have its joints (paperJ when --trajectory is left out), every
// iteration reports the overall RMS and each joint's, and the rigs, which carry one joint, refuse it.
#include <cmath>

#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include "tests/process_runner.hpp"

namespace bellows {
namespace {

using testing::expect_refused_in_one_line;

nlohmann::json joints_run_json(const std::string& args) {
  const auto result = testing::run_process(testing::kBellows + " run --json --quiet --no-save " + args);
  EXPECT_EQ(result.exit_code, 0) << result.err;
  return nlohmann::json::parse(result.out);
}

std::string arm_config(const std::string& name, const std::string& toml) {
  static const auto dir = testing::make_temp_dir("bellows-cli-arms");
  return testing::write_file(dir, name + ".toml", toml).string();
}

TEST(CliJoints, Arm2ReportsEveryJointsRmsAndLearns) {
  const std::string arm2 = arm_config("arm2", "[arm]\npreset = \"arm2\"\n");
  const auto run =
      testing::run_process(testing::kBellows + " run --json --no-save --config " + arm2 + " --iterations 3");
  ASSERT_EQ(run.exit_code, 0) << run.err;
  const nlohmann::json report = nlohmann::json::parse(run.out);
  // The prediction and the wind-up monitor, the arm's and each joint's (issue 26).
  const nlohmann::json& prediction = report.at("prediction");
  ASSERT_TRUE(prediction.at("available").get<bool>()) << prediction.dump();
  EXPECT_EQ(prediction.at("joints_learned"), "together");
  EXPECT_LT(prediction.at("nominal").at("contraction").get<double>(), 1.0);
  ASSERT_EQ(prediction.at("joints").size(), 2u);
  for (const nlohmann::json& joint : prediction.at("joints"))
    EXPECT_LE(joint.at("contraction").get<double>(), prediction.at("nominal").at("contraction").get<double>() + 1e-9);
  ASSERT_EQ(report.at("windup").at("joints").size(), 2u);
  EXPECT_EQ(report.at("iterations")[1].at("joint_diagnostics").size(), 2u);
  EXPECT_NE(run.err.find("convergence prediction (noilc, 2 joints learned together"), std::string::npos) << run.err;
  EXPECT_NE(run.err.find("  joint 2/2 elbow: keeps at most "), std::string::npos) << run.err;
  EXPECT_NE(run.err.find("wind-up monitor, joint 1/2 shoulder: "), std::string::npos) << run.err;
  EXPECT_NE(run.err.find("joint 2/2 elbow: "), std::string::npos) << run.err;
  EXPECT_EQ(report.at("trajectory"), "paper2") << "the arm's paper trajectory when --trajectory is left out";
  EXPECT_EQ(report.at("joints"), 2);
  EXPECT_EQ(report.at("arm").at("name"), "arm2");
  EXPECT_EQ(report.at("arm").at("joint_model"), "coupled");
  ASSERT_EQ(report.at("iterations").size(), 4u);
  std::vector<double> previous = {1e9, 1e9};
  for (const nlohmann::json& it : report.at("iterations")) {
    const std::vector<double> joints = it.at("joint_rms_deg").get<std::vector<double>>();
    ASSERT_EQ(joints.size(), 2u);
    // The overall RMS is over every joint and sample: with N samples each, the joints' RMS combined.
    EXPECT_NEAR(it.at("rms_deg").get<double>(), std::sqrt((joints[0] * joints[0] + joints[1] * joints[1]) / 2.0), 1e-9);
    EXPECT_GE(it.at("max_abs_error_deg").get<double>(), std::max(joints[0], joints[1]));
    for (std::size_t j = 0; j < 2; ++j) {
      EXPECT_LT(joints[j], previous[j]) << "joint " << j + 1 << " at iteration " << it.at("iteration");
      previous[j] = joints[j];
    }
  }
  const std::vector<double> first = report["iterations"][0]["joint_rms_deg"].get<std::vector<double>>();
  EXPECT_GT(first[0], 5.0) << "the shoulder's feedback-only error";
  EXPECT_GT(first[1], 10.0) << "the elbow's: the paper arm's (15 deg)";
  EXPECT_LT(previous[0], 0.6 * first[0]);
  EXPECT_LT(previous[1], 0.6 * first[1]);
}

TEST(CliJoints, Arm3RunsPaper3WithIndependentJointsToo) {
  const std::string arm3 = arm_config("arm3i", "[arm]\npreset = \"arm3\"\n[ilc]\njoint_model = \"independent\"\n");
  const nlohmann::json report = joints_run_json("--config " + arm3 + " --trajectory paper3 --iterations 1");
  EXPECT_EQ(report.at("arm").at("joint_model"), "independent");
  for (const nlohmann::json& it : report.at("iterations")) EXPECT_EQ(it.at("joint_rms_deg").size(), 3u);
  const auto rms = [&](int iteration, int joint) {
    return report["iterations"][iteration]["joint_rms_deg"][joint].get<double>();
  };
  for (int j = 0; j < 3; ++j) EXPECT_LT(rms(1, j), rms(0, j)) << "joint " << j + 1;
}

TEST(CliJoints, AChainOfItsOwnKeysIsTheArmItDescribes) {
  // arm2 written out key by key (multi-joint.md section 2; the shoulder's bellows twice the paper's):
  // the same arm, so the same run to the last bit.
  const std::string own =
      arm_config("own2",
                 "[arm]\njoints = 2\n"
                 "[arm_joint1]\nmass_kg = 0.40\nlength_m = 0.25\ncenter_of_mass_m = 0.125\ninertia_kg_m2 = 2.08e-3\n"
                 "tip_mass_kg = 0.30\nstiffness_Nm_per_rad = 2.81\nkappa_rad_per_bar = 5.0\n"
                 "omega0_straight_rad_per_s = 8.0\nbellows_scale = 2.0\n");
  const std::string arm2 = arm_config("arm2same", "[arm]\npreset = \"arm2\"\n");
  const nlohmann::json by_keys = joints_run_json("--config " + own + " --iterations 2");
  const nlohmann::json by_preset = joints_run_json("--config " + arm2 + " --iterations 2");
  EXPECT_EQ(by_keys.at("arm").at("name"), "[arm] joints = 2");
  EXPECT_EQ(by_keys.at("trajectory"), "paper2");
  ASSERT_EQ(by_keys.at("iterations").size(), 3u);
  for (std::size_t i = 0; i < 3; ++i) {
    EXPECT_EQ(by_keys["iterations"][i]["joint_rms_deg"], by_preset["iterations"][i]["joint_rms_deg"])
        << "iteration " << i;
  }
  // Another shoulder is another arm.
  const std::string light = arm_config("light2", "[arm]\njoints = 2\n[arm_joint1]\nbellows_scale = 2.0\n");
  EXPECT_NE(joints_run_json("--config " + light + " --iterations 0")["iterations"][0]["joint_rms_deg"],
            by_preset["iterations"][0]["joint_rms_deg"]);
}

// Apart from the runs above: a scenario (tests/CMakeLists.txt), while refusals run in every tree.
TEST(CliJoints, AChainOfItsOwnKeysThatIsNoArmIsRefusedInOneLine) {
  expect_refused_in_one_line("run --no-save --config " + arm_config("one", "[arm]\njoints = 1\n"),
                             "[arm] joints = 1: a chain has 2 to 4 joints (leave [arm] out for one joint)");
  expect_refused_in_one_line("run --no-save --config " + arm_config("both", "[arm]\njoints = 3\npreset = \"arm2\"\n"),
                             "[arm] preset and [arm] joints both name the arm: keep one");
  expect_refused_in_one_line(
      "run --no-save --config " + arm_config("faulty", "[arm]\npreset = \"arm2\"\n[plant]\nfault = \"supply-loss\"\n"),
      "[plant] fault = 'supply-loss': the simulated arm of several joints ([arm]) injects no faults");
  expect_refused_in_one_line("run --no-save --config " + arm_config("five", "[arm]\njoints = 5\n"), "[arm] joints = 5");
  expect_refused_in_one_line(
      "run --no-save --config " + arm_config("massless", "[arm]\njoints = 2\n[arm_joint2]\nmass_kg = 0\n"),
      "[arm_joint2] mass_kg = 0");
  expect_refused_in_one_line(
      "run --no-save --config " + arm_config("own2t7", "[arm]\njoints = 2\n") + " --device t7 --t7 127.0.0.1:1",
      "[arm] joints = 2: an arm of several joints runs on --device sim or lcm");
}

TEST(CliJoints, OneJointReportsItsRmsAsItsOnlyJoint) {
  const nlohmann::json report = joints_run_json("--iterations 1");
  EXPECT_EQ(report.at("trajectory"), "paper");
  EXPECT_EQ(report.at("joints"), 1);
  EXPECT_FALSE(report.contains("arm"));
  for (const nlohmann::json& it : report.at("iterations")) {
    ASSERT_EQ(it.at("joint_rms_deg").size(), 1u);
    EXPECT_EQ(it.at("joint_rms_deg")[0].get<double>(), it.at("rms_deg").get<double>());
  }
}

TEST(CliJoints, WhatCannotDriveTheArmIsRefusedInOneLine) {
  const std::string arm2 = arm_config("arm2r", "[arm]\npreset = \"arm2\"\n");
  expect_refused_in_one_line("run --no-save --config " + arm2 + " --trajectory paper",
                             "trajectory 'paper' has 1 joint; the arm has 2 (arm2)");
  expect_refused_in_one_line("run --no-save --config " + arm2 + " --trajectory paper3",
                             "trajectory 'paper3' has 3 joints; the arm has 2 (arm2)");
  expect_refused_in_one_line("run --no-save --config " + arm2 + " --device t7 --t7 127.0.0.1:1",
                             "an arm of several joints runs on --device sim or lcm; --device t7 drives one joint");
  expect_refused_in_one_line(
      "run --no-save --config " + arm_config("bad", "[arm]\npreset = \"arm2\"\n[ilc]\njoint_model = \"rigid\"\n"),
      "[ilc] joint_model = 'rigid': unknown (known: coupled, independent, identified)");
  expect_refused_in_one_line("rig check --config " + arm2, "`bellows rig check` tests the valves of one joint's rig");
  // --transfer-from learns every joint's correction (tests/test_transfer_cli.cpp): a missing session is refused.
  expect_refused_in_one_line("run --no-save --config " + arm2 + " --transfer-from nowhere", "nowhere");
}

}  // namespace
}  // namespace bellows
