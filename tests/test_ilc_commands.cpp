// The binary's learning diagnostics and the identify subcommand, end to end.
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

namespace {

struct Result {
  int status = -1;
  std::string out, err;
};

std::string read_file(const std::filesystem::path& path) {
  std::ifstream in(path);
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

class IlcCommands : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = std::filesystem::temp_directory_path() /
           ("bellows-ilc-" + std::string(::testing::UnitTest::GetInstance()->current_test_info()->name()));
    std::filesystem::create_directories(dir_);
  }
  void TearDown() override { std::filesystem::remove_all(dir_); }

  Result bellows(const std::string& arguments) {
    const auto out = dir_ / "stdout", err = dir_ / "stderr";
    const std::string command =
        std::string(BELLOWS_BINARY) + " " + arguments + " >" + out.string() + " 2>" + err.string();
    Result r;
    const int raw = std::system(command.c_str());
    r.status = WIFEXITED(raw) ? WEXITSTATUS(raw) : -1;
    r.out = read_file(out);
    r.err = read_file(err);
    return r;
  }
  std::filesystem::path write(const std::string& name, const std::string& text) {
    const auto path = dir_ / name;
    std::ofstream(path) << text;
    return path;
  }

  std::filesystem::path dir_;
};

TEST_F(IlcCommands, RunJsonCarriesPredictionAndPerIterationDiagnostics) {
  const Result r = bellows("run --iterations 2 --json");
  ASSERT_EQ(r.status, 0) << r.err;
  const nlohmann::json report = nlohmann::json::parse(r.out);
  EXPECT_EQ(report["law"], "noilc");
  ASSERT_TRUE(report["prediction"]["available"].get<bool>());
  EXPECT_LT(report["prediction"]["nominal"]["contraction"].get<double>(), 1.0);
  EXPECT_EQ(report["prediction"]["grid"].size(), 25u);
  EXPECT_FALSE(report["windup"]["detected"].get<bool>());
  const auto& iterations = report["iterations"];
  ASSERT_EQ(iterations.size(), 3u);
  EXPECT_TRUE(iterations[0]["contraction"].is_null());
  for (int i = 1; i <= 2; ++i) {
    const double contraction = iterations[i]["contraction"].get<double>();
    EXPECT_GT(contraction, 0.3);
    EXPECT_LT(contraction, 1.0);
    EXPECT_GT(iterations[i]["correction_change_bar"].get<double>(), 0.0);
  }
  for (const auto& it : iterations) {
    EXPECT_TRUE(it.contains("saturated_samples"));
    EXPECT_TRUE(it.contains("clamped_excess_bar"));
    EXPECT_TRUE(it.contains("windup_samples"));
  }
}

TEST_F(IlcCommands, RunWarnsBeforeALawPredictedToDiverge) {
  // k_d 20x the default: fails to contract on the simulated arm (test_convergence).
  const auto config = write("pd.toml", "[ilc]\nlaw = \"pd\"\npd_kp = 0.5\npd_kd_s = 0.2\npd_q_cutoff_hz = 5.0\n");
  const Result r = bellows("run --iterations 0 --json --config " + config.string());
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.err.find("warning: learning law 'pd' is predicted to diverge"), std::string::npos) << r.err;
  const nlohmann::json report = nlohmann::json::parse(r.out);
  EXPECT_GT(report["prediction"]["nominal"]["contraction"].get<double>(), 1.0);
  EXPECT_TRUE(report["prediction"]["warning"].is_string());
}

TEST_F(IlcCommands, DefaultRunDoesNotWarn) {
  const Result r = bellows("run --iterations 0 --json");
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(r.err.find("warning"), std::string::npos) << r.err;
  const nlohmann::json report = nlohmann::json::parse(r.out);
  EXPECT_TRUE(report["prediction"]["warning"].is_null());
  EXPECT_LT(report["prediction"]["worst"]["contraction"].get<double>(), 1.0);
}

TEST_F(IlcCommands, UnknownLawIsABadInput) {
  const auto config = write("bad.toml", "[ilc]\nlaw = \"magic\"\n");
  const Result r = bellows("run --iterations 0 --config " + config.string());
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("unknown learning law"), std::string::npos) << r.err;
}

TEST_F(IlcCommands, IdentifyRecoversTheCreepFreeArmAndWritesTheModelSection) {
  const auto plant = write("plant.toml", "[plant]\ncreep_gain = 0.0\n");
  const Result r = bellows("identify --json --config " + plant.string());
  ASSERT_EQ(r.status, 0) << r.err;
  const nlohmann::json report = nlohmann::json::parse(r.out);
  EXPECT_NEAR(report["model"]["kappa"].get<double>(), 7.91, 0.05 * 7.91);
  EXPECT_NEAR(report["model"]["omega0"].get<double>(), 14.14, 0.05 * 14.14);
  EXPECT_NEAR(report["model"]["damping"].get<double>(), 0.31, 0.05 * 0.31);
  EXPECT_GT(report["validation_fit_percent"].get<double>(), 95.0);

  const auto lab = write("lab.toml", "# rig 2\n[model]\nkappa = 7.91  # paper\n");
  // It holds a model (the paper's kappa): replaced only with --force (issue 24), never in silence.
  const Result refused = bellows("identify --write-model " + lab.string());
  EXPECT_EQ(refused.status, 2);
  EXPECT_NE(refused.err.find("holds a model already ([model] kappa = 7.91)"), std::string::npos) << refused.err;
  const Result written = bellows("identify --force --write-model " + lab.string());
  ASSERT_EQ(written.status, 0) << written.err;
  const std::string text = read_file(lab);
  EXPECT_NE(text.find("# rig 2"), std::string::npos) << text;
  EXPECT_NE(text.find("omega0 = "), std::string::npos) << text;
  EXPECT_EQ(text.find("kappa = 7.91  # paper"), std::string::npos) << text;
  const Result run = bellows("run --iterations 1 --config " + lab.string());
  EXPECT_EQ(run.status, 0) << run.err;
}

TEST_F(IlcCommands, IdentifyLeavesAnInvalidConfigUntouched) {
  const std::string original = "[model]\nkappa = \"seven\"\n";
  const auto lab = write("lab.toml", original);
  const Result r = bellows("identify --write-model " + lab.string());
  EXPECT_EQ(r.status, 2);
  EXPECT_EQ(read_file(lab), original);
  EXPECT_EQ(bellows("identify --signal noise").status, 2);
}

TEST_F(IlcCommands, IdentifyFitsThePlantOfTheFileItWritesAndSaysWhich) {
  // A lab's file describes its arm: a stiffer gain than the default plant's 7.91 rad/bar.
  const auto lab = write("rig2.toml", "[plant]\nkappa = 5.0\ncreep_gain = 0.0\n");
  const Result r = bellows("identify --json --write-model " + lab.string());
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.err.find("fitting the plant of " + lab.string()), std::string::npos) << r.err;
  const nlohmann::json report = nlohmann::json::parse(r.out);
  EXPECT_NEAR(report["model"]["kappa"].get<double>(), 5.0, 0.05 * 5.0);
  const Result defaults = bellows("identify --json --signal steps");
  EXPECT_NE(defaults.err.find("fitting the default plant"), std::string::npos) << defaults.err;
}

// `bellows identify` is recorded in a session where runs save theirs: the identification trial (its
// excitation is the session's trajectory, the trial its iteration 0), the held-out trial, the fit and
// what was written where; `sessions show` loads it. --no-save records nothing.
TEST_F(IlcCommands, IdentifyIsRecordedInASession) {
  const auto lab = write("lab.toml", "[identify]\nduration_s = 8.0\n");
  const auto data = dir_ / "data";
  const Result r = bellows("identify --json --config " + lab.string() + " --write-model " + lab.string() +
                           " --data-dir " + data.string() + " --name ident");
  ASSERT_EQ(r.status, 0) << r.err;
  const nlohmann::json report = nlohmann::json::parse(r.out);
  ASSERT_EQ(report["session"], (data / "ident").string());
  EXPECT_NE(r.err.find("session " + (data / "ident").string()), std::string::npos) << r.err;

  const Result shown = bellows("sessions show --json " + (data / "ident").string());
  ASSERT_EQ(shown.status, 0) << shown.err;
  const nlohmann::json session = nlohmann::json::parse(shown.out);
  EXPECT_EQ(session["device"], "sim");
  EXPECT_EQ(session["device_info"]["seed"], 1);
  EXPECT_EQ(session["trajectory"]["name"].get<std::string>().find("chirp") != std::string::npos, true)
      << session["trajectory"];
  ASSERT_EQ(session["iterations"].size(), 1u);  // the identification trial
  EXPECT_TRUE(session["model"]["source"].is_null()) << "identify learns nothing: no model source";
  std::vector<std::string> kinds;
  std::string fit, written;
  for (const nlohmann::json& e : session["events"]) {
    kinds.push_back(e["kind"]);
    if (e["kind"] == "identify-fit") fit = e["message"];
    if (e["kind"] == "model-written") written = e["message"];
  }
  EXPECT_EQ(kinds, (std::vector<std::string>{"start", "identify-trial", "identify-trial", "identify-fit",
                                             "model-written", "finish"}));
  char kappa[32];
  std::snprintf(kappa, sizeof kappa, "kappa %.6g rad/bar", report["model"]["kappa"].get<double>());
  EXPECT_NE(fit.find(kappa), std::string::npos) << fit;
  EXPECT_NE(written.find("into the configuration " + lab.string()), std::string::npos) << written;

  const Result unsaved = bellows("identify --json --no-save --config " + lab.string());
  ASSERT_EQ(unsaved.status, 0) << unsaved.err;
  EXPECT_TRUE(nlohmann::json::parse(unsaved.out)["session"].is_null());
  EXPECT_EQ(std::distance(std::filesystem::directory_iterator(data), std::filesystem::directory_iterator()), 1);
  EXPECT_EQ(bellows("identify --no-save --data-dir " + data.string()).status, 2);  // the two contradict
}

TEST_F(IlcCommands, IdentifyRefusesAModelFileThatIsNotAFile) {
  const auto dir = write("x.toml", "").parent_path() / "a-directory";
  std::filesystem::create_directories(dir);
  const Result r = bellows("identify --write-model " + dir.string());
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("is a directory"), std::string::npos) << r.err;
}

}  // namespace
