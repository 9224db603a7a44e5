// `bellows run --transfer-from SESSION...`: the first trial of a new trajectory runs with what saved
// sessions taught; --json reports the transfer, the session records where its first correction came
// from, and sessions that cannot teach this run are refused with one line naming them (exit 2).
#include <cmath>
#include <fstream>
#include <numbers>
#include <sstream>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "session_test_support.hpp"
#include "sessions/session_store.hpp"
#include "test_transfer_scenarios.hpp"

namespace bellows {
namespace {

using testing::ProcessResult;
using testing::run_bellows;
using testing::TempDir;

/// Two trained sessions (paper, steps) and an unseen trajectory as CSV, made once for all tests.
class TransferCli : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = new TempDir();
    const std::string data = data_dir();
    for (const char* trajectory : {"paper", "steps"}) {
      const ProcessResult r = run_bellows({"run", "--trajectory", trajectory, "--iterations", "10", "--data-dir", data,
                                           "--name", std::string("trained-") + trajectory});
      ASSERT_EQ(r.exit_code, 0) << r.err;
    }
    const Trajectory triangle = testing::unseen_trajectories(Configuration{}.timing.sample_s())[3];
    std::ofstream csv(target_csv());
    csv << "time_s,angle_deg\n";
    for (Eigen::Index k = 0; k <= triangle.learning_samples(); ++k) {
      csv << static_cast<double>(k) * triangle.sample_time_s << "," << triangle.joint(0)(k) * 180.0 / std::numbers::pi
          << "\n";
    }
  }
  static void TearDownTestSuite() { delete dir_; }
  static std::string data_dir() { return (*dir_ / "data").string(); }
  static std::string target_csv() { return (*dir_ / "triangle.csv").string(); }
  static std::string write(const std::string& name, const std::string& text) {
    std::ofstream(*dir_ / name) << text;
    return (*dir_ / name).string();
  }

  static TempDir* dir_;
};
TempDir* TransferCli::dir_ = nullptr;

TEST_F(TransferCli, TheFirstTrialStartsFromWhatTheSessionsTaught) {
  const ProcessResult plain =
      run_bellows({"run", "--trajectory", target_csv(), "--iterations", "0", "--no-save", "--json"});
  ASSERT_EQ(plain.exit_code, 0) << plain.err;
  const double feedback_only = nlohmann::json::parse(plain.out)["iterations"][0]["rms_deg"].get<double>();

  // One source by name, one by directory.
  const ProcessResult r = run_bellows({"run", "--trajectory", target_csv(), "--iterations", "2", "--data-dir",
                                       data_dir(), "--name", "taught", "--transfer-from", "trained-paper",
                                       "--transfer-from", data_dir() + "/trained-steps", "--json"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const nlohmann::json report = nlohmann::json::parse(r.out);
  const nlohmann::json& transfer = report["transfer"];
  ASSERT_TRUE(transfer.is_object()) << r.out;
  ASSERT_EQ(transfer["sources"].size(), 2u);
  EXPECT_EQ(transfer["sources"][0]["session"], "trained-paper");
  EXPECT_EQ(transfer["sources"][1]["trajectory"], "steps");
  EXPECT_EQ(transfer["sources"][1]["trials"], 11);
  EXPECT_EQ(transfer["status"], "transferred") << transfer["reason"];
  EXPECT_TRUE(transfer["method"] == "reference-fir" || transfer["method"] == "basis" ||
              transfer["method"] == "inverse-fir");
  EXPECT_EQ(transfer["method_validation_ratios"].size(), 3u);
  const double first = report["iterations"][0]["rms_deg"].get<double>();
  EXPECT_LT(first, 0.6 * feedback_only);
  EXPECT_LT(transfer["prediction"]["rms_deg"].get<double>(),
            transfer["prediction"]["feedback_only_rms_deg"].get<double>());
  EXPECT_GT(report["iterations"][0]["max_abs_correction_bar"].get<double>(), 0.0);  // iteration 0 ran with it
  EXPECT_NE(r.err.find("transfer from trained-paper, trained-steps: "), std::string::npos) << r.err;

  // The session says where its first correction came from, and its iteration 0 holds it.
  const Session saved = load_session(std::filesystem::path(data_dir()) / "taught");
  ASSERT_TRUE(saved.manifest.first_correction.is_object());
  EXPECT_EQ(saved.manifest.first_correction["status"], "transferred");
  EXPECT_EQ(saved.manifest.first_correction["sources"].size(), 2u);
  EXPECT_GT(saved.iterations[0].record.joint_samples(0).u_ilc_bar.cwiseAbs().maxCoeff(), 0.0);
  // A session started without a transfer has no such field.
  EXPECT_TRUE(load_manifest(std::filesystem::path(data_dir()) / "trained-paper").first_correction.is_null());
}

TEST_F(TransferCli, SessionsThatDoNotFitAreRefusedByNameWithNothingCreated) {
  const std::string other_rate = write("40hz.toml", "[timing]\nticks_per_sample = 5\nsettle_s = 0.2\n");
  const std::string other_arm = write("arm.toml", "[plant]\nkappa = 6.5\n[timing]\nsettle_s = 0.2\n");
  for (const auto& [name, config] : {std::pair{"at-40-hz", other_rate}, std::pair{"other-arm", other_arm}}) {
    ASSERT_EQ(run_bellows({"run", "--iterations", "1", "--config", config, "--data-dir", data_dir(), "--name", name})
                  .exit_code,
              0);
  }
  struct Case {
    std::string source, expected;
  };
  for (const Case& c :
       {Case{"at-40-hz", "sampled every 0.025 s"}, Case{"other-arm", "another simulated arm ([plant] kappa "},
        Case{"no-such-session", "no-such-session"}}) {
    const ProcessResult r =
        run_bellows({"run", "--trajectory", target_csv(), "--iterations", "1", "--data-dir", data_dir(), "--name",
                     "refused", "--transfer-from", "trained-paper", "--transfer-from", c.source});
    EXPECT_EQ(r.exit_code, 2) << c.source << ": " << r.err;
    EXPECT_NE(r.err.find(c.expected), std::string::npos) << r.err;
    EXPECT_NE(r.err.find(c.source), std::string::npos) << r.err;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
    EXPECT_FALSE(std::filesystem::exists(std::filesystem::path(data_dir()) / "refused"));
  }
  const ProcessResult method = run_bellows({"run", "--trajectory", target_csv(), "--name", "refused", "--transfer-from",
                                            "trained-paper", "--data-dir", data_dir(), "--transfer-method", "magic"});
  EXPECT_EQ(method.exit_code, 2) << method.err;
  EXPECT_NE(method.err.find("transfer method must be auto, reference-fir, basis or inverse-fir, not 'magic'"),
            std::string::npos)
      << method.err;
  EXPECT_FALSE(std::filesystem::exists(std::filesystem::path(data_dir()) / "refused"));
}

/// A two-joint trajectory as the CSV `time_s,q1_deg,q2_deg`: the shoulder `a` deg and the elbow `b`
/// deg of a raised-cosine pulse of `period_s`, over 8 s.
std::string two_joint_csv(double a_deg, double b_deg, double period_s) {
  std::ostringstream csv;
  csv << "time_s,q1_deg,q2_deg\n";
  const double T = Configuration{}.timing.sample_s();
  for (int k = 0; k * T <= 8.0 + 1e-9; ++k) {
    const double t = k * T;
    const double phase = std::fmod(t, period_s) / period_s;
    const double shape = 0.5 - 0.5 * std::cos(2.0 * std::numbers::pi * phase);
    csv << t << "," << a_deg * shape << "," << b_deg * shape * (t < 4.0 ? 1.0 : -1.0) << "\n";
  }
  return csv.str();
}

TEST_F(TransferCli, AnArmOfTwoJointsFitsEveryJointsFirstCorrectionOnItsOwn) {
  const std::string arm2 = write("arm2.toml", "[arm]\npreset = \"arm2\"\n");
  const std::string taught = write("arm2-pulses.csv", two_joint_csv(15.0, 25.0, 2.0));
  const std::string target = write("arm2-target.csv", two_joint_csv(10.0, 30.0, 1.6));
  for (const auto& [name, trajectory] :
       {std::pair{"arm2-paper2", std::string("paper2")}, std::pair{"arm2-pulses", taught}}) {
    const ProcessResult r = run_bellows({"run", "--config", arm2, "--trajectory", trajectory, "--iterations", "8",
                                         "--data-dir", data_dir(), "--name", name, "--quiet"});
    ASSERT_EQ(r.exit_code, 0) << r.err;
  }
  const ProcessResult plain =
      run_bellows({"run", "--config", arm2, "--trajectory", target, "--iterations", "0", "--no-save", "--json"});
  ASSERT_EQ(plain.exit_code, 0) << plain.err;
  const nlohmann::json alone = nlohmann::json::parse(plain.out)["iterations"][0];
  const ProcessResult r = run_bellows({"run", "--config", arm2, "--trajectory", target, "--iterations", "0", "--json",
                                       "--data-dir", data_dir(), "--name", "arm2-transferred", "--transfer-from",
                                       "arm2-paper2", "--transfer-from", "arm2-pulses"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const nlohmann::json report = nlohmann::json::parse(r.out);
  const nlohmann::json& transfer = report["transfer"];
  ASSERT_EQ(transfer["joints"].size(), 2u) << transfer.dump();
  ASSERT_EQ(transfer["sources"].size(), 2u);
  const nlohmann::json first = report["iterations"][0];
  bool any = false;
  for (int j = 0; j < 2; ++j) {
    const nlohmann::json& joint = transfer["joints"][j];
    EXPECT_EQ(joint["joint"], j + 1);
    EXPECT_EQ(joint["method_validation_ratios"].size(), 3u) << "every method fitted and validated for this joint";
    if (joint["status"] == "transferred") {
      any = true;
      EXPECT_LT(first["joint_rms_deg"][j].get<double>(), alone["joint_rms_deg"][j].get<double>()) << "joint " << j + 1;
    } else {  // a joint whose fit would not help keeps feedback only, and says why
      EXPECT_EQ(joint["status"], "fallback");
      EXPECT_FALSE(joint["reason"].get<std::string>().empty());
      EXPECT_EQ(joint["max_abs_correction_bar"].get<double>(), 0.0);
    }
  }
  EXPECT_EQ(transfer["status"], any ? "transferred" : "fallback");
  // Nothing transferred: iteration 0 runs with feedback only, as without --transfer-from, bit for bit.
  if (!any) {
    EXPECT_EQ(first["joint_rms_deg"], alone["joint_rms_deg"]);
  }
  const Session saved = load_session(std::filesystem::path(data_dir()) / "arm2-transferred");
  EXPECT_EQ(saved.manifest.first_correction["joints"].size(), 2u) << "the session records every joint's transfer";
  EXPECT_NE(r.err.find("transfer from arm2-paper2, arm2-pulses: joint 1 "), std::string::npos) << r.err;
}

// Apart from the learning above (a scenario, tests/CMakeLists.txt): this refusal runs in every tree.
TEST_F(TransferCli, ASessionOfOneJointCannotTeachAnArmOfTwo) {
  const std::string arm2 = write("arm2.toml", "[arm]\npreset = \"arm2\"\n");
  const std::string target = write("arm2-target.csv", two_joint_csv(10.0, 30.0, 1.6));
  const ProcessResult other = run_bellows({"run", "--config", arm2, "--trajectory", target, "--data-dir", data_dir(),
                                           "--name", "arm2-refused", "--transfer-from", "trained-paper"});
  EXPECT_EQ(other.exit_code, 2) << other.err;
  EXPECT_NE(other.err.find("'trained-paper': it was recorded on another arm (one joint there, 'arm2' here)"),
            std::string::npos)
      << other.err;
}

}  // namespace
}  // namespace bellows
