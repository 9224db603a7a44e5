// Sessions saved by every earlier bellows (tests/fixtures/sessions, one folder each, README.md says
// which bellows wrote it and how) open and resume today. The fixtures are found by listing their
// folder: a fixture added for the next format change is tested without touching this file. Each is
// copied first; the fixtures themselves are never written.
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "engine/control/safety.hpp"
#include "session_test_support.hpp"
#include "sessions/manifest_json.hpp"
#include "sessions/session_store.hpp"
#include "tests/test_support.hpp"

namespace bellows {
namespace {

namespace fs = std::filesystem;
using testing::ProcessResult;
using testing::read_text;
using testing::run_bellows;
using testing::TempDir;

const fs::path kFixtureRoot = fs::path(BELLOWS_SOURCE_DIR) / "tests" / "fixtures" / "sessions";

/// Every fixture session: the folders of kFixtureRoot holding a manifest, sorted by name (oldest first).
std::vector<fs::path> saved_fixture_sessions() {
  std::vector<fs::path> found;
  for (const auto& entry : fs::directory_iterator(kFixtureRoot)) {
    if (entry.is_directory() && fs::exists(entry.path() / "manifest.json")) found.push_back(entry.path());
  }
  std::sort(found.begin(), found.end());
  return found;
}

/// A copy of `fixture` in `dir`, the same name: what the test opens, resumes and may change.
fs::path copy_of_fixture(const fs::path& fixture, const TempDir& dir) {
  const fs::path copy = dir / fixture.filename().string();
  fs::copy(fixture, copy, fs::copy_options::recursive);
  return copy;
}

/// The column `name` of a CSV file as the fixture holds it, parsed here, not by bellows' readers.
std::vector<double> fixture_csv_column(const fs::path& file, const std::string& name) {
  std::istringstream in(read_text(file));
  std::string line;
  std::getline(in, line);
  std::vector<std::string> header;
  std::istringstream names(line);
  for (std::string field; std::getline(names, field, ',');) header.push_back(field);
  const auto at = std::find(header.begin(), header.end(), name);
  EXPECT_NE(at, header.end()) << file << " has no column " << name;
  if (at == header.end()) return {};
  const auto column = static_cast<std::size_t>(at - header.begin());
  std::vector<double> values;
  while (std::getline(in, line)) {
    std::istringstream fields(line);
    std::string field;
    for (std::size_t i = 0; i <= column; ++i) std::getline(fields, field, ',');
    values.push_back(std::stod(field));
  }
  return values;
}

/// A samples file's column of joint `joint` (0-based): "error_deg", "error_deg_j2", ...
std::string joint_column(const std::string& name, int joint) {
  return joint == 0 ? name : name + "_j" + std::to_string(joint + 1);
}

/// The trajectory file's column of joint `joint` (0-based) in a session of `joints` joints:
/// "angle_deg" for one joint, "q1_deg", "q2_deg", ... for several.
std::string trajectory_column(int joint, int joints) {
  return joints == 1 ? "angle_deg" : "q" + std::to_string(joint + 1) + "_deg";
}

/// sqrt(mean(error_deg[1..N]^2)) of joint `joint`, as docs/session-format.md defines a samples file's RMS.
double fixture_rms_deg(const fs::path& samples_file, int joint = 0) {
  const std::vector<double> error = fixture_csv_column(samples_file, joint_column("error_deg", joint));
  double sum = 0.0;
  for (std::size_t k = 1; k < error.size(); ++k) sum += error[k] * error[k];
  return error.size() > 1 ? std::sqrt(sum / static_cast<double>(error.size() - 1)) : 0.0;
}

/// How many files of `folder` start with `prefix`.
int files_starting_with(const fs::path& folder, const std::string& prefix) {
  if (!fs::is_directory(folder)) return 0;
  int count = 0;
  for (const auto& entry : fs::directory_iterator(folder)) {
    if (entry.path().filename().string().rfind(prefix, 0) == 0) ++count;
  }
  return count;
}

TEST(SessionFixtures, EveryFixtureIsDocumentedAndTheFolderIsNotEmpty) {
  const std::vector<fs::path> fixtures = saved_fixture_sessions();
  ASSERT_FALSE(fixtures.empty()) << "no fixture sessions in " << kFixtureRoot;
  const std::string readme = read_text(kFixtureRoot / "README.md");
  for (const fs::path& fixture : fixtures) {
    EXPECT_NE(readme.find(fixture.filename().string()), std::string::npos)
        << fixture.filename() << " is not described in " << kFixtureRoot / "README.md";
  }
}

TEST(SessionFixtures, EveryFixtureLoadsWithTheValuesOfItsOwnFiles) {
  for (const fs::path& fixture : saved_fixture_sessions()) {
    SCOPED_TRACE(fixture.filename().string());
    TempDir dir;
    const fs::path copy = copy_of_fixture(fixture, dir);
    Session session;
    ASSERT_NO_THROW(session = load_session(copy)) << testing::error_of([&] { load_session(copy); });
    const nlohmann::json raw = nlohmann::json::parse(read_text(fixture / "manifest.json"));
    const int on_disk = files_starting_with(fixture / "iterations", "iteration_");
    EXPECT_GT(on_disk, 0);
    ASSERT_EQ(session.iterations.size(), static_cast<std::size_t>(on_disk));
    ASSERT_EQ(raw["iterations"].size(), session.manifest.iterations.size());
    EXPECT_EQ(session.manifest.name, raw["name"].get<std::string>());
    EXPECT_EQ(session.manifest.trajectory_name, raw["trajectory"]["name"].get<std::string>());
    // Every joint's columns (one joint before the J-joint format; `trajectory.joints` after it).
    const int joints = raw["trajectory"].value("joints", 1);
    ASSERT_EQ(session.trajectory.joints(), joints);
    for (std::size_t i = 0; i < session.iterations.size(); ++i) {
      const fs::path samples = fixture / raw["iterations"][i]["samples_file"].get<std::string>();
      EXPECT_DOUBLE_EQ(session.manifest.iterations[i].summary.rms_deg, raw["iterations"][i]["rms_deg"].get<double>());
      ASSERT_EQ(session.iterations[i].joints(), joints);
      const Eigen::MatrixXd next_bar = session.iterations[i].next_corrections_bar();
      for (int j = 0; j < joints; ++j) {
        SCOPED_TRACE("joint " + std::to_string(j + 1));
        const double rms = fixture_rms_deg(samples, j);
        EXPECT_NEAR(session.iterations[i].record.joint_rms_error_deg(j), rms, 1e-9 * std::max(1.0, rms)) << samples;
        const std::vector<double> next = fixture_csv_column(samples, joint_column("u_ilc_next_bar", j));
        ASSERT_EQ(static_cast<std::size_t>(next_bar.rows()) + 1, next.size());
        EXPECT_EQ(next_bar(0, j), next[0]);
        EXPECT_EQ(next_bar(next_bar.rows() - 1, j), next[next.size() - 2]);
      }
    }
    for (int j = 0; j < joints; ++j) {
      const std::vector<double> angle_deg =
          fixture_csv_column(fixture / "trajectory.csv", trajectory_column(j, joints));
      const Eigen::VectorXd& angle_rad = session.trajectory.joint(j);
      ASSERT_EQ(static_cast<std::size_t>(angle_rad.size()), angle_deg.size());
      EXPECT_NEAR(angle_rad(angle_rad.size() - 1) * 180.0 / M_PI, angle_deg.back(), 1e-12) << "joint " << j + 1;
    }
    // A first-format session's clock is taken from the arm's time (docs/session-format.md,
    // "Versions"): where both are recorded, they agree.
    const nlohmann::json& resume = raw["resume"];
    if (resume.contains("clock_ticks") && resume["device"].contains("time_s")) {
      const double tick_s = session.manifest.configuration.timing.tick_s;
      EXPECT_EQ(std::llround(resume["device"]["time_s"].get<double>() / tick_s),
                resume["clock_ticks"].get<long long>());
    }
    const int boxes = files_starting_with(fixture / "faults", "blackbox_");
    ASSERT_EQ(session.black_boxes.size(), static_cast<std::size_t>(boxes));
    for (std::size_t b = 0; b < session.black_boxes.size(); ++b) {
      EXPECT_EQ(session.black_boxes[b].size(),
                fixture_csv_column(fixture / raw["black_boxes"][b]["file"].get<std::string>(), "time_s").size());
      // The fault tick last, whether the file names the fault or gives its code (before 59907e0).
      EXPECT_EQ(fault_name(session.black_boxes[b].back().fault), raw["black_boxes"][b]["fault"].get<std::string>());
    }
    if (raw.contains("first_correction")) {
      EXPECT_EQ(nlohmann::json(session.manifest.first_correction), raw["first_correction"]);
    } else {
      EXPECT_TRUE(session.manifest.first_correction.is_null());
    }
  }
}

TEST(SessionFixtures, EveryJointsControllersAreReadFromEveryFormat) {
  // Joint 1's controllers sit at the top of resume.controller in every version-1 session; a
  // version-1 J-joint session keeps joints 2..J's in the one array there (its key is the reader's).
  // A version-2 (J-joint) session keeps every joint's, joint 1's first, in the one array there.
  int several = 0;
  int version2 = 0;
  for (const fs::path& fixture : saved_fixture_sessions()) {
    SCOPED_TRACE(fixture.filename().string());
    const nlohmann::json raw = nlohmann::json::parse(read_text(fixture / "manifest.json"));
    if (!raw.contains("resume") || !raw["resume"].contains("controller")) continue;
    const SessionManifest manifest = load_manifest(fixture);
    ASSERT_TRUE(manifest.resume && manifest.resume->controller);
    const ControlCore::State& state = *manifest.resume->controller;
    const nlohmann::json& controller = raw["resume"]["controller"];
    const int joints = raw["trajectory"].value("joints", 1);
    ASSERT_EQ(state.joint_count, joints);
    const bool every_joint_in_the_array = raw["schema_version"].get<int>() >= 2;
    std::vector<const nlohmann::json*> saved;
    if (!every_joint_in_the_array) saved.push_back(&controller);
    for (const auto& item : controller.items()) {
      if (item.value().is_array())
        for (const nlohmann::json& joint : item.value()) saved.push_back(&joint);
    }
    ASSERT_EQ(saved.size(), static_cast<std::size_t>(joints));
    for (int j = 0; j < joints; ++j) {
      const nlohmann::json& expected = *saved[static_cast<std::size_t>(j)];
      const ControlCore::JointState& read = state.joints[static_cast<std::size_t>(j)];
      EXPECT_EQ(read.hold_rad, expected["hold_rad"].get<double>()) << "joint " << j + 1;
      EXPECT_EQ(read.pid.integral_s, expected["pid"]["integral_s"].get<double>()) << "joint " << j + 1;
      EXPECT_EQ(read.pressure_b.sum_bar, expected["pressure_b"]["sum_bar"].get<double>()) << "joint " << j + 1;
    }
    several += joints > 1 && !every_joint_in_the_array ? 1 : 0;
    version2 += every_joint_in_the_array ? 1 : 0;
  }
  EXPECT_GT(several, 0) << "a J-joint fixture of schema version 1";
  EXPECT_GT(version2, 0) << "a J-joint fixture of schema version 2";
}

TEST(SessionFixtures, EveryFixtureIsShownAndExported) {
  for (const fs::path& fixture : saved_fixture_sessions()) {
    SCOPED_TRACE(fixture.filename().string());
    TempDir dir;
    const fs::path copy = copy_of_fixture(fixture, dir);
    const ProcessResult shown = run_bellows({"sessions", "show", copy.string()});
    EXPECT_EQ(shown.exit_code, 0) << shown.err;
    const ProcessResult json = run_bellows({"sessions", "show", copy.string(), "--json"});
    ASSERT_EQ(json.exit_code, 0) << json.err;
    const nlohmann::json raw = nlohmann::json::parse(read_text(fixture / "manifest.json"));
    const nlohmann::json report = nlohmann::json::parse(json.out);
    EXPECT_EQ(report["iterations"].size(), raw["iterations"].size());
    // Sessions saved before digests were kept are unverified, not refused; later ones are verified.
    const bool digests = raw["trajectory"].contains("sha256");
    EXPECT_EQ(report["integrity"][digests ? "unverified_files" : "verified_files"], 0) << report["integrity"];
    EXPECT_GT(report["integrity"][digests ? "verified_files" : "unverified_files"], 0) << report["integrity"];
    const fs::path csv = dir / "export.csv";
    const ProcessResult exported =
        run_bellows({"sessions", "export", copy.string(), "--format", "csv", "--output", csv.string()});
    ASSERT_EQ(exported.exit_code, 0) << exported.err;
    const std::size_t rows_per_iteration = fixture_csv_column(fixture / "trajectory.csv", "time_s").size();
    EXPECT_EQ(fixture_csv_column(csv, "iteration").size(), raw["iterations"].size() * rows_per_iteration);
  }
}

TEST(SessionFixtures, EveryFixtureResumesWithOneMoreIterationAndTheEarlierOnesUnchanged) {
  for (const fs::path& fixture : saved_fixture_sessions()) {
    SCOPED_TRACE(fixture.filename().string());
    TempDir dir;
    const fs::path copy = copy_of_fixture(fixture, dir);
    const nlohmann::json before = nlohmann::json::parse(read_text(fixture / "manifest.json"));
    // A fixture whose configuration injects a fault on the simulated arm ([plant] fault, at a device
    // time) meets it again: the resume continues the arm's clock exactly, so the next trial faults
    // as the saved run did, and keeps the new black box beside the saved ones.
    const nlohmann::json* plant =
        before["configuration"].contains("plant") ? &before["configuration"]["plant"] : nullptr;
    const bool faults_again = plant != nullptr && plant->contains("fault") && (*plant)["fault"] != "none";
    const ProcessResult resumed = run_bellows({"run", "--resume", copy.string(), "--iterations", "1"});
    ASSERT_EQ(resumed.exit_code, faults_again ? 3 : 0) << resumed.err;
    Session session;
    ASSERT_NO_THROW(session = load_session(copy)) << testing::error_of([&] { load_session(copy); });
    const std::size_t earlier = before["iterations"].size();
    const std::size_t boxes = before.contains("black_boxes") ? before["black_boxes"].size() : 0;
    if (faults_again) {
      EXPECT_EQ(session.manifest.iterations.size(), earlier);
      ASSERT_EQ(session.manifest.black_boxes.size(), boxes + 1);
      EXPECT_EQ(session.manifest.black_boxes.back().fault, before["black_boxes"].back()["fault"].get<std::string>());
      EXPECT_EQ(session.manifest.events.back().kind, "fault");
    } else {
      ASSERT_EQ(session.manifest.iterations.size(), earlier + 1);
      EXPECT_EQ(session.manifest.black_boxes.size(), boxes);
      EXPECT_EQ(session.manifest.events.back().kind, "finish");
    }
    const nlohmann::json after = nlohmann::json::parse(read_text(copy / "manifest.json"));
    for (std::size_t i = 0; i < earlier; ++i) {
      for (const char* key : {"samples_file", "telemetry_file"}) {
        const std::string file = before["iterations"][i][key].get<std::string>();
        EXPECT_EQ(read_text(copy / file), read_text(fixture / file)) << file << " changed";
      }
      for (const char* key : {"iteration", "completed_utc", "rms_deg", "max_abs_error_deg", "max_abs_correction_bar",
                              "saturated_samples"}) {
        EXPECT_EQ(after["iterations"][i][key], before["iterations"][i][key]) << "iteration " << i << " " << key;
      }
    }
    for (std::size_t b = 0; b < boxes; ++b) {
      const std::string file = before["black_boxes"][b]["file"].get<std::string>();
      EXPECT_EQ(read_text(copy / file), read_text(fixture / file)) << file << " changed";
    }
    EXPECT_EQ(read_text(copy / "trajectory.csv"), read_text(fixture / "trajectory.csv"));
    EXPECT_EQ(after["name"], before["name"]);
    EXPECT_EQ(after["started_utc"], before["started_utc"]);
    // Every key the fixture saved keeps its value; keys added since hold their defaults (as in a TOML file).
    for (const auto& [section, keys] : before["configuration"].items()) {
      for (const auto& [key, value] : keys.items())
        EXPECT_EQ(after["configuration"][section][key], value) << section << "." << key;
    }
    if (faults_again) continue;
    // The new iteration ran, on every joint, with the correction the fixture's last iteration learned.
    for (int j = 0; j < before["trajectory"].value("joints", 1); ++j) {
      const std::vector<double> saved_next =
          fixture_csv_column(fixture / before["iterations"][earlier - 1]["samples_file"].get<std::string>(),
                             joint_column("u_ilc_next_bar", j));
      const std::vector<double> applied = fixture_csv_column(
          copy / after["iterations"][earlier]["samples_file"].get<std::string>(), joint_column("u_ilc_bar", j));
      EXPECT_EQ(applied, saved_next) << "joint " << j + 1;
    }
  }
}

TEST(SessionVersions, AFirstFormatResumeStateIsWrittenBackAsItWasRead) {
  const fs::path first = kFixtureRoot / "2026-11-21-1afa6a9-plain";
  const SessionManifest read = load_manifest(first);
  ASSERT_TRUE(read.resume && read.resume->exact());
  EXPECT_FALSE(read.resume->clock_ticks.has_value());
  // Rewritten (a resume records its event before its first iteration) without "exact", which
  // would claim recorded clock ticks, and read again the same way.
  const nlohmann::json written = nlohmann::json::parse(format_manifest(read));
  EXPECT_FALSE(written["resume"].contains("exact"));
  EXPECT_FALSE(written["resume"].contains("clock_ticks"));
  const SessionManifest again = parse_manifest(format_manifest(read), "rewritten");
  ASSERT_TRUE(again.resume && again.resume->exact());
  EXPECT_FALSE(again.resume->clock_ticks.has_value());
}

TEST(SessionVersions, AFirstFormatArmTimeThatCannotBeTheClocksIsRefusedInOneLine) {
  TempDir dir;
  const fs::path copy = copy_of_fixture(kFixtureRoot / "2026-11-21-1afa6a9-plain", dir);
  nlohmann::ordered_json manifest = nlohmann::ordered_json::parse(read_text(copy / "manifest.json"));
  manifest["resume"]["device"]["time_s"] = -0.5;
  testing::write_text(copy / "manifest.json", manifest.dump(2));
  const ProcessResult resumed = run_bellows({"run", "--resume", copy.string(), "--iterations", "1"});
  EXPECT_EQ(resumed.exit_code, 2) << resumed.err;
  EXPECT_NE(resumed.err.find("/resume/device/time_s"), std::string::npos) << resumed.err;
  EXPECT_EQ(std::count(resumed.err.begin(), resumed.err.end(), '\n'), 1) << resumed.err;
  EXPECT_EQ(load_manifest(copy).iterations.size(), 3u);  // nothing lost
}

TEST(SessionVersions, OnlyVersionsFromTheOldestToTheCurrentAreRead) {
  nlohmann::json manifest =
      nlohmann::json::parse(read_text(kFixtureRoot / "2026-11-30-3060f58-plain" / "manifest.json"));
  for (int version = kOldestSessionSchemaVersion; version <= kSessionSchemaVersion; ++version) {
    manifest["schema_version"] = version;
    EXPECT_EQ(parse_manifest(manifest.dump(), "m").schema_version, version);
  }
  manifest["schema_version"] = kSessionSchemaVersion + 1;
  const std::string newer = testing::error_of([&] { parse_manifest(manifest.dump(), "m"); });
  EXPECT_NE(newer.find("is not supported"), std::string::npos) << newer;
  EXPECT_NE(newer.find("a newer bellows wrote it"), std::string::npos) << newer;
  EXPECT_EQ(newer.find('\n'), std::string::npos) << newer;
  manifest["schema_version"] = kOldestSessionSchemaVersion - 1;
  const std::string older = testing::error_of([&] { parse_manifest(manifest.dump(), "m"); });
  EXPECT_NE(older.find("is not supported"), std::string::npos) << older;
  EXPECT_EQ(older.find("newer bellows"), std::string::npos) << older;
}

}  // namespace
}  // namespace bellows
