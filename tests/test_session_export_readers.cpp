// The exports as other tools read them: scipy's loadmat and Octave's load read every field of the
// MAT v5 file with the values of the session's own files, and the recipes of
// docs/session-format.md (pandas, scipy, Octave, PlotJuggler) run as printed there against an
// exported session. Uses Debian's python3-scipy, python3-pandas and octave (scripts/setup.sh).
#include <gtest/gtest.h>

#include <charconv>
#include <cstdio>
#include <sstream>

#include <nlohmann/json.hpp>

#include "sessions/manifest_json.hpp"
#include "sessions/session_export.hpp"
#include "sessions/session_layout.hpp"
#include "tests/session_export_fixture.hpp"

namespace bellows {
namespace {

namespace fs = std::filesystem;
using Json = nlohmann::ordered_json;
using testing::TempDir;

// Debian's interpreter (with python3-scipy, python3-pandas), not whichever python3 is first on PATH.
constexpr const char* kPython = "/usr/bin/python3";
// --no-history: without it Octave 7 ends with a spurious "error: ignoring const
// execution_exception& while preparing to exit" (Octave bug #62515), even after success.
constexpr const char* kOctave = "octave-cli --no-gui -q --no-window-system --no-history";

struct Output {
  int status = -1;
  std::string text;  // stdout and stderr
};

Output run_in(const fs::path& directory, const std::string& command) {
  const std::string line = "cd '" + directory.string() + "' && " + command + " 2>&1";
  FILE* pipe = ::popen(line.c_str(), "r");
  Output out;
  if (pipe == nullptr) return out;
  char buffer[4096];
  for (std::size_t n; (n = std::fread(buffer, 1, sizeof buffer, pipe)) > 0;) out.text.append(buffer, n);
  const int status = ::pclose(pipe);
  out.status = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  return out;
}

fs::path recipes() { return fs::path(BELLOWS_SOURCE_DIR) / "tests" / "recipes"; }

/// A CSV file's columns as JSON arrays: numbers where every field is one (nan kept), names otherwise.
Json columns_of(const fs::path& file) {
  std::istringstream in(testing::read_text(file));
  std::string line;
  std::getline(in, line);
  std::vector<std::string> names;
  for (std::stringstream header(line); std::getline(header, line, ',');) names.push_back(line);
  std::vector<std::vector<std::string>> fields(names.size());
  while (std::getline(in, line)) {
    std::stringstream row(line);
    for (auto& column : fields) {
      std::getline(row, line, ',');
      column.push_back(line);
    }
  }
  Json out = Json::object();
  for (std::size_t c = 0; c < names.size(); ++c) {
    Json numbers = Json::array(), texts = Json::array();
    bool numeric = true;
    for (const std::string& field : fields[c]) {
      double value = 0;
      const auto [end, error] = std::from_chars(field.data(), field.data() + field.size(), value);
      numeric = numeric && error == std::errc() && end == field.data() + field.size();
      numbers.push_back(std::isnan(value) ? Json("NaN") : Json(value));  // a literal NaN after dump()
      texts.push_back(field);
    }
    out[names[c]] = numeric ? numbers : texts;
  }
  return out;
}

/// What the MAT file must hold, built from the session's own files and manifest.
std::string expected_mat_json(const Session& session) {
  const SessionManifest& m = session.manifest;
  const fs::path& dir = session.directory;
  Json summary = {{"iteration", Json::array()},
                  {"rms_deg", Json::array()},
                  {"max_abs_error_deg", Json::array()},
                  {"max_abs_correction_bar", Json::array()},
                  {"saturated_samples", Json::array()}};
  Json iterations = Json::array();
  for (std::size_t i = 0; i < m.iterations.size(); ++i) {
    const IterationSummary& s = m.iterations[i].summary;
    summary["iteration"].push_back(s.iteration);
    summary["rms_deg"].push_back(s.rms_deg);
    summary["max_abs_error_deg"].push_back(s.max_abs_error_deg);
    summary["max_abs_correction_bar"].push_back(s.max_abs_correction_bar);
    summary["saturated_samples"].push_back(s.saturated_samples);
    iterations.push_back({{"iteration", s.iteration},
                          {"rms_deg", s.rms_deg},
                          {"max_abs_error_deg", s.max_abs_error_deg},
                          {"max_abs_correction_bar", s.max_abs_correction_bar},
                          {"saturated_samples", s.saturated_samples},
                          {"completed_utc", m.iterations[i].completed_utc},
                          {"samples", columns_of(dir / session_layout::samples_file(static_cast<int>(i)))},
                          {"telemetry", columns_of(dir / session_layout::telemetry_file(static_cast<int>(i)))}});
  }
  Json events = Json::array();
  for (const SessionEvent& e : m.events) {
    events.push_back({{"time_utc", e.time_utc}, {"iteration", e.iteration}, {"kind", e.kind}, {"message", e.message}});
  }
  Json trajectory = columns_of(dir / session_layout::kTrajectory);
  Json boxes = Json::array();
  for (std::size_t b = 0; b < m.black_boxes.size(); ++b) {
    const BlackBoxEntry& e = m.black_boxes[b];
    boxes.push_back({{"fault", e.fault},
                     {"iteration", e.iteration},
                     {"time_utc", e.time_utc},
                     {"ticks", columns_of(dir / session_layout::black_box_file(static_cast<int>(b)))}});
  }
  const Json expected = {
      {"session",
       {{"name", m.name},
        {"program_version", m.program_version},
        {"device", m.device},
        {"started_utc", m.started_utc},
        {"updated_utc", m.updated_utc},
        {"configuration", configuration_to_json(m.configuration)},
        {"trajectory",
         {{"name", m.trajectory_name}, {"time_s", trajectory["time_s"]}, {"angle_deg", trajectory["angle_deg"]}}},
        {"summary", summary},
        {"events", events}}},
      {"iterations", iterations},
      {"black_boxes", boxes}};
  std::string text = expected.dump(1);
  for (std::size_t at; (at = text.find("\"NaN\"")) != std::string::npos;) text.replace(at, 5, "NaN");
  return text;
}

class SessionReaders : public ::testing::Test {
 protected:
  void SetUp() override {
    session_ = testing::saved_faulted_session(dir_ / "paper-run");
    testing::write_text(dir_ / "expected.json", expected_mat_json(session_));
  }
  TempDir dir_;
  Session session_;
};

TEST_F(SessionReaders, ScipyReadsEveryFieldOfMatV5) {
  export_session_mat(session_, dir_ / "session.mat");
  const Output out = run_in(dir_.path(), std::string(kPython) + " " + (recipes() / "check_mat_scipy.py").string() +
                                             " session.mat expected.json");
  EXPECT_EQ(out.status, 0) << out.text;
  EXPECT_EQ(out.text, "scipy read 3 variables; every field agrees\n");
  // ...and a damaged expectation is caught (the checker can fail).
  std::string wrong = testing::read_text(dir_ / "expected.json");
  wrong.replace(wrong.find("\"sensor-nan\""), 12, "\"overpressure\"");
  testing::write_text(dir_ / "wrong.json", wrong);
  EXPECT_EQ(run_in(dir_.path(),
                   std::string(kPython) + " " + (recipes() / "check_mat_scipy.py").string() + " session.mat wrong.json")
                .status,
            1);
}

TEST_F(SessionReaders, OctaveReadsEveryFieldOfMatV5) {
  export_session_mat(session_, dir_ / "session.mat");
  const std::string check = std::string(kOctave) + " " + (recipes() / "check_mat_octave.m").string();
  const Output out = run_in(dir_.path(), check + " session.mat expected.json");
  EXPECT_EQ(out.status, 0) << out.text;
  EXPECT_EQ(out.text, "octave read 3 variables; every field agrees\n");
  std::string wrong = testing::read_text(dir_ / "expected.json");
  wrong.replace(wrong.find("\"completed_utc\": \"") + 18, 4, "1999");
  testing::write_text(dir_ / "wrong.json", wrong);
  EXPECT_EQ(run_in(dir_.path(), check + " session.mat wrong.json").status, 1);
}

/// The code block of docs/session-format.md that follows `marker`, which must be `file` verbatim.
void expect_documented(const std::string& marker, const fs::path& file) {
  const std::string docs = testing::read_text(fs::path(BELLOWS_SOURCE_DIR) / "docs" / "session-format.md");
  const std::size_t at = docs.find(marker);
  ASSERT_NE(at, std::string::npos) << marker;
  const std::size_t start = docs.find('\n', docs.find("```", at)) + 1;
  const std::size_t end = docs.find("```", start);
  EXPECT_EQ(docs.substr(start, end - start), testing::read_text(file)) << file << " differs from the docs";
}

TEST_F(SessionReaders, TheRecipesRunAsDocumented) {
  export_session_csv(session_, dir_ / "session.csv");
  export_session_mat(session_, dir_ / "session.mat");
  fs::create_directory_symlink(session_.directory, dir_ / "session");  // the recipes' session folder
  char rms[64];
  std::snprintf(rms, sizeof rms, "%.4f", session_.manifest.iterations.back().summary.rms_deg);
  const std::string expected = "3 iterations, last RMS " + std::string(rms) + " deg\n";

  expect_documented("<!-- recipe: pandas -->", recipes() / "pandas_recipe.py");
  Output out = run_in(dir_.path(), std::string(kPython) + " " + (recipes() / "pandas_recipe.py").string());
  EXPECT_EQ(out.status, 0) << out.text;
  EXPECT_EQ(out.text,
            expected + "black box: sensor-nan at tick " + std::to_string(session_.black_boxes[0].back().tick) + "\n");

  expect_documented("<!-- recipe: scipy -->", recipes() / "scipy_recipe.py");
  out = run_in(dir_.path(), std::string(kPython) + " " + (recipes() / "scipy_recipe.py").string());
  EXPECT_EQ(out.status, 0) << out.text;
  EXPECT_EQ(out.text, expected + "black box: sensor-nan, last state FAULT\n");

  expect_documented("<!-- recipe: octave -->", recipes() / "octave_recipe.m");
  out = run_in(dir_.path(), std::string(kOctave) + " " + (recipes() / "octave_recipe.m").string());
  EXPECT_EQ(out.status, 0) << out.text;
  EXPECT_EQ(out.text, expected + "black box: sensor-nan, last state FAULT\n");

  // PlotJuggler's CSV loader needs a time column that increases row by row: every per-iteration
  // file has one (the stacked export restarts it each iteration, so the recipe points at these).
  out = run_in(dir_.path(), std::string(kPython) + " " + (recipes() / "plotjuggler_check.py").string());
  EXPECT_EQ(out.status, 0) << out.text;
  EXPECT_EQ(out.text, "7 files with an increasing time_s\n");  // 3 x (samples, telemetry) + the black box
}

}  // namespace
}  // namespace bellows
