// `bellows identify` on an arm of several joints (app/identify_chain) as a user runs it: every joint
// excited in turn, each joint's single-joint fit, the coupled model validated on held-out trials and
// compared with the chain's linearization; --write-model hands the coupled model to `bellows run`
// (`[ilc] joint_model = "identified"`), and what still cannot work is refused in one line.
#include <fstream>
#include <map>
#include <sstream>

#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include "tests/process_runner.hpp"

namespace bellows {
namespace {

std::string identify_arm_config(const std::string& name, const std::string& toml) {
  static const auto dir = testing::make_temp_dir("bellows-cli-identify-arms");
  return testing::write_file(dir, name + ".toml", toml).string();
}

std::vector<double> numbers(const nlohmann::json& array) { return array.get<std::vector<double>>(); }

TEST(CliIdentifyJoints, Arm2FitsEveryJointAndTheCoupledModelAndComparesItWithTheLinearization) {
  const std::string arm2 = identify_arm_config("arm2", "[arm]\npreset = \"arm2\"\n");
  const auto data_dir = testing::make_temp_dir("bellows-cli-identify-sessions");
  const auto result = testing::run_process(testing::kBellows + " identify --json --config " + arm2 + " --data-dir " +
                                           data_dir.string() + " --name arm2-identified");
  ASSERT_EQ(result.exit_code, 0) << result.err;
  for (const char* line : {"joint 1 of 2: identification trial (chirp", "joint 2 of 2: held-out trial (steps",
                           "fitting the coupled model (4 states)"}) {
    EXPECT_NE(result.err.find(line), std::string::npos) << line << "\n" << result.err;
  }
  const nlohmann::json report = nlohmann::json::parse(result.out);
  EXPECT_EQ(report.at("arm"), "arm2");
  EXPECT_EQ(report.at("joints"), 2);
  EXPECT_EQ(report.at("validation_signal"), "steps");
  ASSERT_EQ(report.at("joint_models").size(), 2u);
  for (const nlohmann::json& joint : report.at("joint_models")) {
    // Each joint's own fit beats its row of the arm's table on the held-out trial (the table ignores
    // the joints' coupling, creep and the bellows).
    EXPECT_GT(joint.at("validation_fit_percent").get<double>(), 75.0) << joint.dump();
    EXPECT_GT(joint.at("validation_fit_percent").get<double>(),
              joint.at("arm_model_validation_fit_percent").get<double>() + 2.0);
  }
  const nlohmann::json& coupled = report.at("coupled_model");
  EXPECT_EQ(coupled.at("states"), 4);
  EXPECT_EQ(coupled.at("per_bar_rad_per_s2").size(), 2u);
  const std::vector<double> held_out = numbers(coupled.at("validation_fit_percent"));
  const std::vector<double> linearized = numbers(report.at("linearization").at("validation_fit_percent"));
  const std::vector<double> independent = numbers(report.at("independent_validation_fit_percent"));
  ASSERT_EQ(held_out.size(), 2u);
  for (std::size_t j = 0; j < 2; ++j) {
    EXPECT_GT(held_out[j], 80.0) << "joint " << j + 1;
    EXPECT_GT(held_out[j], linearized[j] + 5.0)
        << "joint " << j + 1 << ": the linearization leaves out creep and the bellows";
    EXPECT_GT(held_out[j], independent[j]) << "joint " << j + 1 << ": the coupling is worth fitting";
  }
  // The identified model is near the linearization, not equal to it.
  const double gap = report.at("linearization_gap").at("markov_relative").get<double>();
  EXPECT_GT(gap, 0.02);
  EXPECT_LT(gap, 0.5);
  // The session: joint 1's trial as iteration 0 (of both joints), every trial, fit and the gap as events.
  ASSERT_EQ(report.at("session"), (data_dir / "arm2-identified").string());
  std::stringstream manifest_text;
  manifest_text << std::ifstream(data_dir / "arm2-identified" / "manifest.json").rdbuf();
  const nlohmann::json manifest = nlohmann::json::parse(manifest_text.str());
  std::map<std::string, int> kinds;
  for (const nlohmann::json& event : manifest.at("events")) ++kinds[event.at("kind").get<std::string>()];
  EXPECT_EQ(kinds["identify-trial"], 4);  // 2 joints x (identification, held-out)
  EXPECT_EQ(kinds["identify-fit"], 3);    // each joint, then the coupled model
  EXPECT_EQ(kinds["identify-gap"], 1);
  EXPECT_EQ(kinds["finish"], 1);
  EXPECT_EQ(manifest.at("iterations").size(), 1u);
}

TEST(CliIdentifyJoints, TheIdentifiedCoupledModelIsWhatARunLearnsWith) {
  const std::string arm2 = identify_arm_config("arm2w", "# my arm\n[arm]\npreset = \"arm2\"\n");
  const auto identified =
      testing::run_process(testing::kBellows + " identify --no-save --config " + arm2 + " --write-model " + arm2);
  ASSERT_EQ(identified.exit_code, 0) << identified.err;
  // Without --json the progress lines go to stdout with the results.
  EXPECT_NE(identified.out.find("wrote [identified_joint1..2] and [ilc] joint_model = \"identified\""),
            std::string::npos)
      << identified.out;
  std::stringstream text;
  text << std::ifstream(arm2).rdbuf();
  for (const char* expected : {"# my arm", "[identified_joint1]", "[identified_joint2]", "per_bar_j2_rad_per_s2",
                               "joint_model = \"identified\""}) {
    EXPECT_NE(text.str().find(expected), std::string::npos) << expected << "\n" << text.str();
  }
  const auto run =
      testing::run_process(testing::kBellows + " run --json --quiet --no-save --iterations 5 --config " + arm2);
  ASSERT_EQ(run.exit_code, 0) << run.err;
  const nlohmann::json report = nlohmann::json::parse(run.out);
  EXPECT_EQ(report.at("arm").at("joint_model"), "identified");
  const std::vector<double> first = numbers(report["iterations"][0]["joint_rms_deg"]);
  const std::vector<double> fifth = numbers(report["iterations"][5]["joint_rms_deg"]);
  for (std::size_t j = 0; j < 2; ++j) EXPECT_LT(fifth[j], 0.3 * first[j]) << "joint " << j + 1;
}

TEST(CliIdentifyJoints, WhatCannotWorkIsRefusedInOneLine) {
  const std::string arm2 = identify_arm_config("arm2r", "[arm]\npreset = \"arm2\"\n");
  testing::expect_refused_in_one_line(
      "identify --no-save --config " + arm2 + " --device t7 --t7 127.0.0.1:1",
      "an arm of several joints runs on --device sim or lcm; --device t7 drives one joint");
  const std::string one_joint = identify_arm_config("one", "[model]\nkappa = 7.0\n");
  testing::expect_refused_in_one_line(
      "identify --no-save --config " + arm2 + " --write-model " + one_joint,
      "its arm is one joint, not arm2; write the coupled model into the arm's configuration");
  testing::expect_refused_in_one_line(
      "run --no-save --config " +
          identify_arm_config("none", "[arm]\npreset = \"arm2\"\n[ilc]\njoint_model = \"identified\"\n"),
      "[ilc] joint_model = 'identified': [identified_joint1] holds no identified model");
}

}  // namespace
}  // namespace bellows
