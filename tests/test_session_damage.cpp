// Damaged sessions: every kind of damage is refused with one clear line naming the session, the
// file and what is wrong, by the library, by `bellows sessions show` and by `bellows run --resume`
// (exit status 2), and a refused resume writes nothing.
#include <cctype>
#include <cmath>
#include <functional>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "engine/base/errors.hpp"
#include "session_test_support.hpp"
#include "sessions/file_digest.hpp"
#include "sessions/session_layout.hpp"
#include "sessions/session_store.hpp"
#include "tests/test_support.hpp"

namespace bellows {
namespace {

using testing::TempDir;
namespace fs = std::filesystem;

using testing::error_of;

struct Damage {
  const char* name;
  std::function<void(const fs::path&)> apply;
  const char* expected;  // part of the error
};

void edit_manifest(const fs::path& dir, const std::function<void(nlohmann::ordered_json&)>& edit) {
  auto json = nlohmann::ordered_json::parse(testing::read_text(dir / "manifest.json"));
  edit(json);
  testing::write_text(dir / "manifest.json", json.dump(2));
}

void replace_in(const fs::path& file, const std::string& from, const std::string& to) {
  std::string text = testing::read_text(file);
  const auto at = text.find(from);
  ASSERT_NE(at, std::string::npos) << from;
  text.replace(at, from.size(), to);
  testing::write_text(file, text);
}

/// Digests that match the damaged files, as in a session damaged before it was saved (or saved
/// before digests were kept): so each damage reaches the check it is about, not the digest check
/// (tests/test_session_hostile.cpp tests that one).
void refresh_digests(const fs::path& dir) {
  nlohmann::ordered_json json;
  try {
    json = nlohmann::ordered_json::parse(testing::read_text(dir / "manifest.json"));
  } catch (const nlohmann::json::exception&) {
    return;
  }
  bool changed = false;
  const auto refresh = [&](nlohmann::ordered_json& object, const char* key, const std::string& relative) {
    if (!object.is_object() || !object.contains(key) || !fs::is_regular_file(dir / relative)) return;
    const std::string digest = sha256_hex(testing::read_text(dir / relative));
    changed = changed || object[key] != digest;
    object[key] = digest;
  };
  if (!json.is_object()) return;
  refresh(json["trajectory"], "sha256", "trajectory.csv");
  if (json.contains("iterations") && json["iterations"].is_array()) {
    for (std::size_t i = 0; i < json["iterations"].size(); ++i) {
      refresh(json["iterations"][i], "samples_sha256", session_layout::samples_file(static_cast<int>(i)));
      refresh(json["iterations"][i], "telemetry_sha256", session_layout::telemetry_file(static_cast<int>(i)));
    }
  }
  if (changed) testing::write_text(dir / "manifest.json", json.dump(2));
}

std::vector<Damage> damages() {
  const auto samples = [](const fs::path& d) { return d / session_layout::samples_file(1); };
  const auto telemetry = [](const fs::path& d) { return d / session_layout::telemetry_file(0); };
  return {
      {"manifest missing", [](const fs::path& d) { fs::remove(d / "manifest.json"); }, "manifest.json is missing"},
      {"manifest not JSON", [](const fs::path& d) { testing::write_text(d / "manifest.json", "this is not json\n"); },
       "manifest.json: not valid JSON"},
      {"manifest empty", [](const fs::path& d) { testing::write_text(d / "manifest.json", ""); }, "not valid JSON"},
      {"manifest truncated",
       [](const fs::path& d) {
         const std::string text = testing::read_text(d / "manifest.json");
         testing::write_text(d / "manifest.json", text.substr(0, text.size() / 2));
       },
       "not valid JSON"},
      {"not a session manifest", [](const fs::path& d) { testing::write_text(d / "manifest.json", "[1, 2]"); },
       "not a bellows session manifest"},
      {"schema version too new", [](const fs::path& d) { edit_manifest(d, [](auto& j) { j["schema_version"] = 3; }); },
       "schema version 3 is not supported (this bellows reads versions 1 to 2)"},
      {"schema version missing",
       [](const fs::path& d) { edit_manifest(d, [](auto& j) { j.erase("schema_version"); }); },
       "missing \"schema_version\""},
      {"NaN in the manifest",
       [](const fs::path& d) { edit_manifest(d, [](auto& j) { j["iterations"][1]["rms_deg"] = NAN; }); },
       "/iterations/1/rms_deg: expected a number, found null"},
      {"string for a number",
       [](const fs::path& d) { edit_manifest(d, [](auto& j) { j["configuration"]["ilc"]["m"] = "one"; }); },
       "/configuration/ilc/m: expected a number"},
      {"invalid configuration",
       [](const fs::path& d) {
         edit_manifest(d, [](auto& j) { j["configuration"]["controller"]["p_max_bar"] = 0.9; });
       },
       "[controller] p_max_bar = 0.9: must be above ambient pressure"},
      {"unknown configuration key",
       [](const fs::path& d) { edit_manifest(d, [](auto& j) { j["configuration"]["ilc"]["horizon"] = 3; }); },
       "unknown key \"horizon\""},
      {"iterations misnumbered",
       [](const fs::path& d) { edit_manifest(d, [](auto& j) { j["iterations"][1]["iteration"] = 5; }); },
       "iterations must be numbered 0, 1, 2, ...: expected 1, found 5"},
      {"file outside the layout",
       [](const fs::path& d) {
         edit_manifest(d, [](auto& j) { j["iterations"][0]["samples_file"] = "../../etc/passwd"; });
       },
       "/iterations/0/samples_file: expected \"iterations/iteration_0000.csv\""},
      {"resume does not match",
       [](const fs::path& d) { edit_manifest(d, [](auto& j) { j["resume"]["next_iteration"] = 7; }); },
       "/resume/next_iteration: expected 3"},
      {"resume missing", [](const fs::path& d) { edit_manifest(d, [](auto& j) { j.erase("resume"); }); },
       "missing \"resume\""},
      {"controller state out of range",
       [](const fs::path& d) {
         edit_manifest(d, [](auto& j) { j["resume"]["controller"]["pressure_a"]["next"] = 40; });
       },
       "/resume/controller/pressure_a/next: expected a whole number in [0, 3]"},
      {"samples file missing", [=](const fs::path& d) { fs::remove(samples(d)); },
       "iterations/iteration_0001.csv is missing"},
      {"samples truncated mid-line",
       [=](const fs::path& d) {
         const std::string text = testing::read_text(samples(d));
         testing::write_text(samples(d), text.substr(0, text.size() - 7));
       },
       "iteration_0001.csv: truncated: line 27 has no end of line"},
      {"samples short of rows",
       [=](const fs::path& d) {
         const std::string text = testing::read_text(samples(d));
         testing::write_text(samples(d), text.substr(0, text.rfind('\n', text.size() - 2) + 1));
       },
       "iteration_0001.csv: expected 26 rows (the trajectory's learning samples + 1), found 25"},
      {"telemetry with an extra row",
       [=](const fs::path& d) {
         std::string text = testing::read_text(telemetry(d));
         testing::write_text(telemetry(d), text + text.substr(text.rfind('\n', text.size() - 2) + 1));
       },
       "telemetry_0000.csv: expected 100 rows (learning samples times ticks per sample), found 101"},
      {"NaN in the samples", [=](const fs::path& d) { replace_in(samples(d), "\n0.1,", "\nnan,"); },
       "is not a finite number"},
      {"wrong header", [=](const fs::path& d) { replace_in(samples(d), "u_pid_bar", "u_p_bar"); },
       "line 1: the header must be"},
      {"samples disagree with the manifest",
       [](const fs::path& d) { edit_manifest(d, [](auto& j) { j["iterations"][1]["rms_deg"] = 99.0; }); },
       "differs from the manifest's"},
      {"trajectory missing", [](const fs::path& d) { fs::remove(d / "trajectory.csv"); }, "trajectory.csv is missing"},
      {"trajectory of another length",
       [](const fs::path& d) { edit_manifest(d, [](auto& j) { j["trajectory"]["learning_samples"] = 30; }); },
       "trajectory.csv: expected 31 rows"},
      {"manifest is a directory",
       [](const fs::path& d) {
         fs::remove(d / "manifest.json");
         fs::create_directory(d / "manifest.json");
       },
       "manifest.json is a directory, not a regular file"},
  };
}

class BadSession : public ::testing::TestWithParam<Damage> {};

TEST_P(BadSession, IsRefusedWithAClearError) {
  TempDir dir;
  save_session(testing::simulate_session(3), dir / "s");
  GetParam().apply(dir / "s");
  refresh_digests(dir / "s");
  const std::string error = error_of([&] { load_session(dir / "s"); });
  EXPECT_NE(error.find(GetParam().expected), std::string::npos) << error;
  EXPECT_EQ(error.rfind("session " + (dir / "s").string(), 0), 0u) << error;  // names the session first
  // `bellows sessions show` says the same on one line and exits with status 2.
  const testing::ProcessResult shown = testing::run_bellows({"sessions", "show", (dir / "s").string()});
  EXPECT_EQ(shown.exit_code, 2);
  EXPECT_EQ(shown.out, "");
  EXPECT_EQ(shown.err, "bellows: " + error + "\n");
  // And a resume refuses it the same way, writing nothing.
  const std::string manifest_before =
      fs::is_regular_file(dir / "s" / "manifest.json") ? testing::read_text(dir / "s" / "manifest.json") : "";
  const testing::ProcessResult resumed =
      testing::run_bellows({"run", "--resume", (dir / "s").string(), "--iterations", "1"});
  EXPECT_EQ(resumed.exit_code, 2);
  EXPECT_EQ(resumed.err, "bellows: " + error + "\n");
  if (!manifest_before.empty()) {
    EXPECT_EQ(testing::read_text(dir / "s" / "manifest.json"), manifest_before);
  }
}

INSTANTIATE_TEST_SUITE_P(Damages, BadSession, ::testing::ValuesIn(damages()),
                         [](const ::testing::TestParamInfo<Damage>& param_info) {
                           std::string name = param_info.param.name;
                           for (char& c : name) {
                             if (!std::isalnum(static_cast<unsigned char>(c))) c = '_';
                           }
                           return name;
                         });

TEST(BadSessionPath, AMissingDirectoryIsAClearError) {
  const testing::ProcessResult shown = testing::run_bellows({"sessions", "show", "/nonexistent/session"});
  EXPECT_EQ(shown.exit_code, 2);
  EXPECT_NE(shown.err.find("session /nonexistent/session: no such directory"), std::string::npos) << shown.err;
}

}  // namespace
}  // namespace bellows
