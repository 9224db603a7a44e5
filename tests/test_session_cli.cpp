// `bellows run` saving and resuming, and `bellows sessions list|show|export`, driven through the
// binary as an operator or a script would. Every test saves into its own temporary directory.
#include <signal.h>
#include <sys/wait.h>

#include <cmath>

#include <gtest/gtest.h>
#include <matio.h>
#include <nlohmann/json.hpp>

#include "session_test_support.hpp"
#include "sessions/csv_table.hpp"
#include "sessions/iteration_files.hpp"
#include "sessions/session_lock.hpp"
#include "sessions/session_store.hpp"
#include "tests/test_support.hpp"

namespace bellows {
namespace {

using testing::ProcessResult;
using testing::run_bellows;
using testing::TempDir;
namespace fs = std::filesystem;

nlohmann::json run_json(const std::vector<std::string>& args) {
  const ProcessResult result = run_bellows(args);
  EXPECT_EQ(result.exit_code, 0) << result.err;
  return nlohmann::json::parse(result.out);
}

std::vector<std::string> short_run(const TempDir& dir, std::vector<std::string> extra) {
  std::vector<std::string> args = {"run", "--trajectory", (dir / "short.csv").string(), "--config",
                                   (dir / "short.toml").string()};
  args.insert(args.end(), extra.begin(), extra.end());
  return args;
}

TEST(SessionResume, TenIterationsEqualFivePlusAResumeOfFive) {
  TempDir dir;
  const std::string data = (dir / "data").string();
  const nlohmann::json whole = run_json({"run", "--iterations", "10", "--data-dir", data, "--name", "whole", "--json"});
  const nlohmann::json first = run_json({"run", "--iterations", "5", "--data-dir", data, "--name", "split", "--json"});
  const nlohmann::json rest = run_json({"run", "--resume", data + "/split", "--iterations", "5", "--json"});
  EXPECT_EQ(rest["session"], data + "/split");
  ASSERT_EQ(whole["iterations"].size(), 11u);
  ASSERT_EQ(first["iterations"].size(), 6u);
  ASSERT_EQ(rest["iterations"].size(), 5u);
  std::vector<nlohmann::json> split(first["iterations"].begin(), first["iterations"].end());
  split.insert(split.end(), rest["iterations"].begin(), rest["iterations"].end());
  for (std::size_t i = 0; i < split.size(); ++i) {
    EXPECT_EQ(split[i]["iteration"], static_cast<int>(i));
    EXPECT_NEAR(split[i]["rms_deg"].get<double>(), whole["iterations"][i]["rms_deg"].get<double>(), 1e-9) << i;
    EXPECT_NEAR(split[i]["max_abs_correction_bar"].get<double>(),
                whole["iterations"][i]["max_abs_correction_bar"].get<double>(), 1e-9)
        << i;
  }
  // The saved signals agree too, sample for sample, and the learning improved things.
  const Session a = load_session(dir / "data" / "whole");
  const Session b = load_session(dir / "data" / "split");
  ASSERT_EQ(a.iterations.size(), 11u);
  ASSERT_EQ(b.iterations.size(), 11u);
  for (std::size_t i = 0; i < 11; ++i) {
    EXPECT_EQ(a.iterations[i].record.joint_samples(0).angle_rad, b.iterations[i].record.joint_samples(0).angle_rad)
        << i;
    EXPECT_EQ(a.iterations[i].record.joint_ticks(0).pressure_a_bar,
              b.iterations[i].record.joint_ticks(0).pressure_a_bar)
        << i;
    EXPECT_EQ(a.iterations[i].next_corrections_bar(), b.iterations[i].next_corrections_bar()) << i;
  }
  EXPECT_LT(split.back()["rms_deg"].get<double>(), 0.5 * split.front()["rms_deg"].get<double>());
  const auto& events = b.manifest.events;
  ASSERT_EQ(events.size(), 4u);
  EXPECT_EQ(events[0].kind, "start");
  EXPECT_EQ(events[1].kind, "finish");
  EXPECT_EQ(events[2].kind, "resume");
  EXPECT_EQ(events[2].iteration, 6);
  EXPECT_EQ(events[3].kind, "finish");
}

TEST(SessionResume, FindsASessionByNameInTheDataDirectory) {
  TempDir dir;
  testing::write_short_run_files(dir.path());
  const std::string data = (dir / "data").string();
  ASSERT_EQ(run_bellows(short_run(dir, {"--iterations", "1", "--data-dir", data, "--name", "mine"})).exit_code, 0);
  const ProcessResult resumed = run_bellows({"run", "--resume", "mine", "--data-dir", data, "--iterations", "2"});
  EXPECT_EQ(resumed.exit_code, 0) << resumed.err;
  EXPECT_NE(resumed.out.find("iteration   3"), std::string::npos) << resumed.out;
  EXPECT_EQ(load_session(dir / "data" / "mine").iterations.size(), 4u);
}

TEST(SessionResume, RefusesOptionsThatWouldChangeTheSession) {
  for (const std::vector<std::string>& extra : {std::vector<std::string>{"--trajectory", "sine"},
                                                {"--config", "x.toml"},
                                                {"--seed", "3"},
                                                {"--no-save"},
                                                {"--name", "other"}}) {
    std::vector<std::string> args = {"run", "--resume", "/tmp/somewhere", "--iterations", "1"};
    args.insert(args.end(), extra.begin(), extra.end());
    const ProcessResult result = run_bellows(args);
    EXPECT_EQ(result.exit_code, 2) << extra[0];
    EXPECT_NE(result.err.find("excludes"), std::string::npos) << result.err;
  }
}

TEST(SessionSaving, DefaultsToTheXdgDataDirectory) {
  TempDir dir;
  testing::write_short_run_files(dir.path());
  const std::string xdg = "XDG_DATA_HOME=" + (dir / "xdg").string();
  const ProcessResult result = run_bellows(short_run(dir, {"--iterations", "1"}), {xdg});
  ASSERT_EQ(result.exit_code, 0) << result.err;
  const fs::path sessions = dir / "xdg" / "bellows" / "sessions";
  const std::vector<SessionListing> listings = list_sessions(sessions);
  ASSERT_EQ(listings.size(), 1u);
  EXPECT_NE(result.out.find("session " + listings[0].directory.string() + "\n"), std::string::npos) << result.out;
  EXPECT_EQ(listings[0].manifest.trajectory_name, "short");
  EXPECT_EQ(listings[0].manifest.iterations.size(), 2u);
  EXPECT_EQ(listings[0].directory.filename().string().substr(19), "_short");  // "YYYY-MM-DD_hh-mm-ss_short"
}

TEST(SessionSaving, FallsBackToTheHomeDirectory) {
  TempDir dir;
  testing::write_short_run_files(dir.path());
  const ProcessResult result = run_bellows(short_run(dir, {"--iterations", "0", "--name", "h"}),
                                           {"XDG_DATA_HOME", "HOME=" + dir.path().string()});
  ASSERT_EQ(result.exit_code, 0) << result.err;
  EXPECT_EQ(load_session(dir / ".local/share/bellows/sessions/h").iterations.size(), 1u);
}

TEST(SessionSaving, NoSaveWritesNothing) {
  TempDir dir;
  testing::write_short_run_files(dir.path());
  const ProcessResult result =
      run_bellows(short_run(dir, {"--iterations", "1", "--no-save"}),
                  {"XDG_DATA_HOME=" + (dir / "xdg").string(), "HOME=" + (dir / "home").string()});
  ASSERT_EQ(result.exit_code, 0) << result.err;
  EXPECT_EQ(result.out.find("session"), std::string::npos);
  EXPECT_FALSE(fs::exists(dir / "xdg"));
  EXPECT_FALSE(fs::exists(dir / "home"));
}

TEST(SessionSaving, AnUnusableDataDirectoryIsAClearError) {
  TempDir dir;
  testing::write_short_run_files(dir.path());
  testing::write_text(dir / "file", "not a directory");
  const ProcessResult result =
      run_bellows(short_run(dir, {"--iterations", "0", "--data-dir", (dir / "file").string()}));
  EXPECT_EQ(result.exit_code, 2);
  EXPECT_NE(result.err.find("bellows: cannot create the data directory " + (dir / "file").string()), std::string::npos)
      << result.err;
}

TEST(SessionSaving, ANameInUseIsRefused) {
  TempDir dir;
  testing::write_short_run_files(dir.path());
  const std::string data = (dir / "data").string();
  ASSERT_EQ(run_bellows(short_run(dir, {"--iterations", "0", "--data-dir", data, "--name", "n"})).exit_code, 0);
  const ProcessResult again = run_bellows(short_run(dir, {"--iterations", "0", "--data-dir", data, "--name", "n"}));
  EXPECT_EQ(again.exit_code, 2);
  EXPECT_NE(again.err.find("session " + data + "/n exists already; continue it with --resume"), std::string::npos)
      << again.err;
  const ProcessResult bad_name =
      run_bellows(short_run(dir, {"--iterations", "0", "--data-dir", data, "--name", "a/b"}));
  EXPECT_EQ(bad_name.exit_code, 2);
  EXPECT_NE(bad_name.err.find("must be a plain directory name"), std::string::npos) << bad_name.err;
}

/// Reads a spawned process's stdout until `text` appears (or the output ends).
using testing::read_until;

TEST(SessionLocking, ASecondProcessIsRefusedAndTheFirstNamed) {
  TempDir dir;
  testing::write_short_run_files(dir.path());
  const std::string data = (dir / "data").string();
  const testing::Spawned first =
      testing::spawn_bellows(short_run(dir, {"--iterations", "100000", "--data-dir", data, "--name", "busy"}));
  const std::string started = read_until(first.out, "iteration   1");
  ASSERT_NE(started.find("iteration   1"), std::string::npos) << started;
  const std::string holder = "is in use by bellows run (pid " + std::to_string(first.pid);
  const ProcessResult resume = run_bellows({"run", "--resume", data + "/busy", "--iterations", "1"});
  EXPECT_EQ(resume.exit_code, 2);
  EXPECT_NE(resume.err.find("bellows: session " + data + "/busy " + holder), std::string::npos) << resume.err;
  const ProcessResult same_name =
      run_bellows(short_run(dir, {"--iterations", "0", "--data-dir", data, "--name", "busy"}));
  EXPECT_EQ(same_name.exit_code, 2);
  EXPECT_NE(same_name.err.find(holder), std::string::npos) << same_name.err;
  ::kill(first.pid, SIGKILL);
  ::waitpid(first.pid, nullptr, 0);
  ::close(first.out);
  ::close(first.err);
  const ProcessResult after = run_bellows({"run", "--resume", data + "/busy", "--iterations", "1"});
  EXPECT_EQ(after.exit_code, 0) << after.err;
}

TEST(SessionSaving, AFaultIsRecordedAndEveryCompletedIterationKept) {
  TempDir dir;
  testing::write_short_run_files(dir.path());
  const std::string data = (dir / "data").string();
  const testing::Spawned run =
      testing::spawn_bellows(short_run(dir, {"--iterations", "100000", "--data-dir", data, "--name", "f"}));
  const std::string out = read_until(run.out, "iteration   2");
  ASSERT_NE(out.find("iteration   2"), std::string::npos) << out;
  ::kill(run.pid, SIGINT);  // the engine vents and the run stops with a fault: emergency stop
  int status = 0;
  ::waitpid(run.pid, &status, 0);
  ::close(run.out);
  ::close(run.err);
  EXPECT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 128 + SIGINT) << status;
  const Session session = load_session(dir / "data" / "f");
  EXPECT_GE(session.iterations.size(), 3u);
  ASSERT_FALSE(session.manifest.events.empty());
  const SessionEvent& last = session.manifest.events.back();
  EXPECT_EQ(last.kind, "fault");
  EXPECT_EQ(last.iteration, static_cast<int>(session.iterations.size()));
  EXPECT_NE(last.message.find("interrupted"), std::string::npos) << last.message;
}

TEST(SessionSaving, AGuardsFaultKeepsItsBlackBoxWhichShowPrints) {
  TempDir dir;
  testing::write_short_run_files(dir.path());
  // Supply lost 0.9 s in: during iteration 1 (each trial is 0.05 s of settle and 0.5 s of moves).
  testing::write_text(dir / "short.toml",
                      "[timing]\nsettle_s = 0.05\n[plant]\nfault = \"supply-loss\"\nfault_at_s = 0.9\n");
  const std::string data = (dir / "data").string();
  const ProcessResult run = run_bellows(short_run(dir, {"--iterations", "5", "--data-dir", data, "--name", "f"}));
  EXPECT_EQ(run.exit_code, 3) << run.err;
  const Session session = load_session(dir / "data" / "f");
  ASSERT_EQ(session.manifest.black_boxes.size(), 1u);
  const BlackBoxEntry& entry = session.manifest.black_boxes[0];
  EXPECT_EQ(entry.fault, "supply-low");
  EXPECT_EQ(entry.iteration, static_cast<int>(session.iterations.size()));
  ASSERT_EQ(session.black_boxes[0].size(), static_cast<std::size_t>(entry.ticks));
  const TickRecord& fault_tick = session.black_boxes[0].back();
  EXPECT_EQ(fault_tick.state, EngineState::kFault);
  EXPECT_EQ(fault_tick.fault, FaultCode::kSupplyLow);
  EXPECT_LT(fault_tick.reading.supply_bar, session.manifest.configuration.safety.supply_min_bar);
  EXPECT_GE(session.black_boxes[0].front().reading.supply_bar, session.manifest.configuration.safety.supply_min_bar);

  const ProcessResult shown = run_bellows({"sessions", "show", (dir / "data" / "f").string()});
  EXPECT_EQ(shown.exit_code, 0) << shown.err;
  EXPECT_NE(shown.out.find("black boxes"), std::string::npos) << shown.out;
  EXPECT_NE(shown.out.find("0: supply-low during iteration"), std::string::npos) << shown.out;
  EXPECT_NE(shown.out.find("<- supply-low"), std::string::npos) << shown.out;
  const nlohmann::json json = run_json({"sessions", "show", (dir / "data" / "f").string(), "--json"});
  ASSERT_EQ(json["black_boxes"].size(), 1u);
  EXPECT_EQ(json["black_boxes"][0]["file"], "faults/blackbox_0000.csv");
  EXPECT_EQ(json["black_boxes"][0]["ticks"], entry.ticks);
}

TEST(SessionSaving, AWallClockRunSavesAndResumesWithItsCorrection) {
  TempDir dir;
  testing::write_short_run_files(dir.path());
  const std::string data = (dir / "data").string();
  const ProcessResult wall = run_bellows(
      short_run(dir, {"--clock", "wall", "--speed", "max", "--iterations", "1", "--data-dir", data, "--name", "w"}));
  ASSERT_EQ(wall.exit_code, 0) << wall.err;
  const Session saved = load_session(dir / "data" / "w");
  ASSERT_EQ(saved.iterations.size(), 2u);
  ASSERT_TRUE(saved.manifest.resume.has_value());
  EXPECT_FALSE(saved.manifest.resume->exact());  // the loop thread owned the state: not captured
  const ProcessResult resumed = run_bellows({"run", "--resume", data + "/w", "--iterations", "1"});
  ASSERT_EQ(resumed.exit_code, 0) << resumed.err;
  const Session continued = load_session(dir / "data" / "w");
  ASSERT_EQ(continued.iterations.size(), 3u);
  EXPECT_EQ(continued.iterations[2].record.joint_samples(0).u_ilc_bar.head(25),
            saved.iterations[1].next_corrections_bar());
}

class SessionsCommand : public ::testing::Test {
 protected:
  void SetUp() override {
    testing::write_short_run_files(dir_.path());
    data_ = (dir_ / "data").string();
    first_ = run_json(short_run(dir_, {"--iterations", "3", "--data-dir", data_, "--name", "first", "--json"}));
    run_json(short_run(dir_, {"--iterations", "1", "--data-dir", data_, "--name", "second", "--json", "--seed", "4"}));
  }
  TempDir dir_;
  std::string data_;
  nlohmann::json first_;
};

TEST_F(SessionsCommand, ListIsATableAndJson) {
  const ProcessResult table = run_bellows({"sessions", "list", "--data-dir", data_});
  ASSERT_EQ(table.exit_code, 0) << table.err;
  EXPECT_EQ(table.out.rfind("NAME", 0), 0u);
  EXPECT_NE(table.out.find("TRAJECTORY"), std::string::npos);
  EXPECT_NE(table.out.find("BEST RMS"), std::string::npos);
  const auto first_line = table.out.find("\nfirst ");
  ASSERT_NE(first_line, std::string::npos) << table.out;
  const std::string row = table.out.substr(first_line + 1, table.out.find('\n', first_line + 1) - first_line - 1);
  EXPECT_NE(row.find(" sim "), std::string::npos) << row;
  EXPECT_NE(row.find(" short "), std::string::npos) << row;
  EXPECT_NE(row.find(" 0..3 "), std::string::npos) << row;  // `run --iterations 3`: iterations 0..3

  EXPECT_LT(table.out.find("\nsecond "), first_line);  // newest first, as the console's browser

  const nlohmann::json list =
      nlohmann::json::parse(run_bellows({"sessions", "list", "--data-dir", data_, "--json"}).out);
  ASSERT_EQ(list.size(), 2u);
  EXPECT_EQ(list[0]["name"], "second");
  EXPECT_EQ(list[1]["name"], "first");
  EXPECT_EQ(list[1]["iterations"], 4);  // a count, of iterations 0..3 (docs/iterations.md)
  EXPECT_EQ(list[1]["last_iteration"], 3);
  EXPECT_EQ(list[1]["device"], "sim");
  EXPECT_EQ(list[1]["trajectory"], "short");
  double best = 1e9;
  for (const auto& iteration : first_["iterations"]) best = std::min(best, iteration["rms_deg"].get<double>());
  EXPECT_EQ(list[1]["best_rms_deg"].get<double>(), best);

  // An empty data directory has no sessions; a missing one is a typo, refused (test_cli_conventions).
  fs::create_directories(dir_ / "none");
  const ProcessResult empty = run_bellows({"sessions", "list", "--data-dir", (dir_ / "none").string()});
  EXPECT_EQ(empty.exit_code, 0);
  EXPECT_EQ(empty.out, "no sessions in " + (dir_ / "none").string() + "\n");
}

TEST_F(SessionsCommand, ListFlagsABadSessionAndGoesOn) {
  fs::create_directories(dir_ / "data" / "junk");
  testing::write_text(dir_ / "data" / "junk" / "manifest.json", "{");
  const ProcessResult table = run_bellows({"sessions", "list", "--data-dir", data_, "--json"});
  EXPECT_EQ(table.exit_code, 0);
  EXPECT_NE(table.err.find("bellows: warning: session " + data_ + "/junk: manifest.json: not valid JSON"),
            std::string::npos)
      << table.err;
  const nlohmann::json list = nlohmann::json::parse(table.out);
  ASSERT_EQ(list.size(), 3u);
  int flagged = 0;
  for (const auto& entry : list) flagged += entry.contains("error");
  EXPECT_EQ(flagged, 1);
}

TEST_F(SessionsCommand, ShowGivesTheSummaryAndRmsPerIteration) {
  const ProcessResult shown = run_bellows({"sessions", "show", data_ + "/first"});
  ASSERT_EQ(shown.exit_code, 0) << shown.err;
  EXPECT_NE(shown.out.find("trajectory   short: 25 samples"), std::string::npos) << shown.out;
  EXPECT_NE(shown.out.find("learning     " + Configuration{}.ilc.law + ", m = 1, s = 0.1"), std::string::npos)
      << shown.out;
  for (const auto& iteration : first_["iterations"]) {
    char row[64];
    std::snprintf(row, sizeof row, "%9d  %9.3f", iteration["iteration"].get<int>(), iteration["rms_deg"].get<double>());
    EXPECT_NE(shown.out.find(row), std::string::npos) << row;
  }
  const nlohmann::json json =
      nlohmann::json::parse(run_bellows({"sessions", "show", "first", "--data-dir", data_, "--json"}).out);
  EXPECT_EQ(json["name"], "first");
  EXPECT_EQ(json["device_info"]["seed"], 1);
  ASSERT_EQ(json["iterations"].size(), 4u);
  for (std::size_t i = 0; i < 4; ++i) EXPECT_EQ(json["iterations"][i]["rms_deg"], first_["iterations"][i]["rms_deg"]);
  EXPECT_EQ(json["events"][0]["kind"], "start");
  EXPECT_EQ(json["learning"]["law"], Configuration{}.ilc.law);
  EXPECT_EQ(json["learning"]["w"], 2e-5);
}

TEST_F(SessionsCommand, ExportsCsvThatReadsBack) {
  const fs::path out = dir_ / "export" / "first.csv";
  fs::create_directories(out.parent_path());
  const ProcessResult result =
      run_bellows({"sessions", "export", data_ + "/first", "--format", "csv", "--output", out.string(), "--json"});
  ASSERT_EQ(result.exit_code, 0) << result.err;
  const nlohmann::json report = nlohmann::json::parse(result.out);
  ASSERT_EQ(report["files"].size(), 3u);
  std::vector<std::string_view> header = {"iteration"};
  for (std::string_view column : samples_columns()) header.push_back(column);
  const auto samples = parse_csv(testing::read_text(out), header, "export");
  ASSERT_EQ(samples[0].size(), 4 * 26);
  const Session session = load_session(dir_ / "data" / "first");
  for (int i = 0; i < 4; ++i) {
    for (int k = 0; k < 26; ++k) {
      EXPECT_EQ(samples[0](i * 26 + k), i);
      EXPECT_EQ(radians_from_degrees(samples[3](i * 26 + k)),
                session.iterations[i].record.joint_samples(0).angle_rad(k));
    }
  }
  std::vector<std::string_view> telemetry_header = {"iteration"};
  for (std::string_view column : telemetry_columns()) telemetry_header.push_back(column);
  const auto telemetry = parse_csv(testing::read_text(dir_ / "export" / "first_telemetry.csv"), telemetry_header, "t");
  EXPECT_EQ(telemetry[0].size(), 4 * 100);
  const auto summary =
      parse_csv(testing::read_text(dir_ / "export" / "first_summary.csv"),
                {"iteration", "rms_deg", "max_abs_error_deg", "max_abs_correction_bar", "saturated_samples"}, "s");
  for (int i = 0; i < 4; ++i) EXPECT_EQ(summary[1](i), first_["iterations"][i]["rms_deg"].get<double>());
}

/// Reads a double column from a struct field of a MAT variable.
std::vector<double> mat_column(matvar_t* parent, const char* field, std::size_t index) {
  matvar_t* var = Mat_VarGetStructFieldByName(parent, field, index);
  if (var == nullptr || var->class_type != MAT_C_DOUBLE) return {};
  const double* data = static_cast<const double*>(var->data);
  return std::vector<double>(data, data + var->dims[0] * var->dims[1]);
}

TEST_F(SessionsCommand, ExportsMatlabV73WithOneStructPerIteration) {
  const fs::path out = dir_ / "first.mat";
  const ProcessResult result = run_bellows(
      {"sessions", "export", data_ + "/first", "--format", "mat", "--mat-version", "7.3", "--output", out.string()});
  ASSERT_EQ(result.exit_code, 0) << result.err;
  EXPECT_EQ(result.out, "wrote " + out.string() + "\n");
  mat_t* file = Mat_Open(out.c_str(), MAT_ACC_RDONLY);
  ASSERT_NE(file, nullptr);
  EXPECT_EQ(Mat_GetVersion(file), MAT_FT_MAT73);
  matvar_t* iterations = Mat_VarRead(file, "iterations");
  ASSERT_NE(iterations, nullptr);
  EXPECT_EQ(iterations->class_type, MAT_C_STRUCT);
  EXPECT_EQ(iterations->dims[0] * iterations->dims[1], 4u);
  const Session session = load_session(dir_ / "data" / "first");
  for (std::size_t i = 0; i < 4; ++i) {
    EXPECT_EQ(mat_column(iterations, "rms_deg", i),
              std::vector<double>{session.manifest.iterations[i].summary.rms_deg});
    matvar_t* samples = Mat_VarGetStructFieldByName(iterations, "samples", i);
    ASSERT_NE(samples, nullptr);
    const std::vector<double> angle = mat_column(samples, "angle_deg", 0);
    const std::vector<double> u_tot = mat_column(samples, "u_tot_bar", 0);
    ASSERT_EQ(angle.size(), 26u);
    ASSERT_EQ(u_tot.size(), 26u);
    for (int k = 0; k < 26; ++k) {
      EXPECT_EQ(radians_from_degrees(angle[k]), session.iterations[i].record.joint_samples(0).angle_rad(k));
      EXPECT_EQ(u_tot[k], session.iterations[i].record.joint_samples(0).u_total_bar(k));
    }
    matvar_t* telemetry = Mat_VarGetStructFieldByName(iterations, "telemetry", i);
    ASSERT_NE(telemetry, nullptr);
    EXPECT_EQ(mat_column(telemetry, "inlet_a_duty", 0).size(), 100u);
  }
  Mat_VarFree(iterations);
  matvar_t* meta = Mat_VarRead(file, "session");
  ASSERT_NE(meta, nullptr);
  matvar_t* configuration = Mat_VarGetStructFieldByName(meta, "configuration", 0);
  ASSERT_NE(configuration, nullptr);
  EXPECT_EQ(mat_column(Mat_VarGetStructFieldByName(configuration, "ilc", 0), "s", 0), std::vector<double>{0.1});
  matvar_t* trajectory = Mat_VarGetStructFieldByName(meta, "trajectory", 0);
  EXPECT_EQ(mat_column(trajectory, "angle_deg", 0).size(), 26u);
  Mat_VarFree(meta);
  Mat_Close(file);
}

TEST_F(SessionsCommand, ExportRejectsAnUnknownFormat) {
  const ProcessResult result = run_bellows({"sessions", "export", data_ + "/first", "--format", "xlsx"});
  EXPECT_EQ(result.exit_code, 2);
  EXPECT_NE(result.err.find("--format"), std::string::npos) << result.err;
}

TEST_F(SessionsCommand, RmAsksFirstAndRemovesOnlyWhenConfirmed) {
  const std::string first = data_ + "/first";
  // No answer (stdin at its end): nothing removed, exit status 1.
  const ProcessResult unanswered = run_bellows({"sessions", "rm", "first", "--data-dir", data_});
  EXPECT_EQ(unanswered.exit_code, 1);
  EXPECT_NE(unanswered.err.find("remove session " + first + " (iterations 0..3"), std::string::npos) << unanswered.err;
  EXPECT_NE(unanswered.err.find("not removed"), std::string::npos) << unanswered.err;
  EXPECT_TRUE(fs::exists(first));
  const ProcessResult yes = run_bellows({"sessions", "rm", "first", "--data-dir", data_, "--yes"});
  EXPECT_EQ(yes.exit_code, 0) << yes.err;
  EXPECT_EQ(yes.out, "removed " + first + "\n");
  EXPECT_FALSE(fs::exists(first));
  EXPECT_EQ(list_sessions(dir_ / "data").size(), 1u);
  // Never a directory that is not a session.
  fs::create_directories(dir_ / "data" / "photos");
  const ProcessResult other = run_bellows({"sessions", "rm", "photos", "--data-dir", data_, "--yes"});
  EXPECT_EQ(other.exit_code, 2);
  EXPECT_NE(other.err.find("is not a bellows session"), std::string::npos) << other.err;
  EXPECT_TRUE(fs::exists(dir_ / "data" / "photos"));
}

TEST_F(SessionsCommand, RmRefusesASessionInUse) {
  const SessionLock lock(dir_ / "data" / "first", "bellows run");
  const ProcessResult result = run_bellows({"sessions", "rm", "first", "--data-dir", data_, "--yes"});
  EXPECT_EQ(result.exit_code, 2);
  EXPECT_NE(result.err.find("in use"), std::string::npos) << result.err;
  EXPECT_TRUE(fs::exists(dir_ / "data" / "first"));
}

TEST_F(SessionsCommand, RenameMovesTheSessionAndItsManifestName) {
  const ProcessResult result = run_bellows({"sessions", "rename", "first", "paper-run", "--data-dir", data_});
  ASSERT_EQ(result.exit_code, 0) << result.err;
  EXPECT_FALSE(fs::exists(dir_ / "data" / "first"));
  const Session renamed = load_session(dir_ / "data" / "paper-run");
  EXPECT_EQ(renamed.manifest.name, "paper-run");
  EXPECT_EQ(renamed.iterations.size(), 4u);
  const ProcessResult taken = run_bellows({"sessions", "rename", "paper-run", "second", "--data-dir", data_});
  EXPECT_EQ(taken.exit_code, 2);
  EXPECT_NE(taken.err.find("exists already"), std::string::npos) << taken.err;
  const ProcessResult bad = run_bellows({"sessions", "rename", "paper-run", "a/b", "--data-dir", data_});
  EXPECT_EQ(bad.exit_code, 2);
  EXPECT_TRUE(fs::exists(dir_ / "data" / "paper-run"));
}

}  // namespace
}  // namespace bellows
