// Hostile sessions (issue 16): a session folder someone else could write into. Links, special files
// and edits are each refused with one line and exit status 2 by `sessions show`, `list`, `export`
// and `run --resume`; nothing is written or deleted outside the session (the link targets are
// checked unchanged); nothing hangs (every process runs under a guard that kills and flags it).
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cstdlib>
#include <functional>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "session_test_support.hpp"
#include "sessions/file_digest.hpp"
#include "sessions/session_layout.hpp"
#include "sessions/session_store.hpp"

namespace bellows {
namespace {

using testing::ProcessResult;
using testing::run_bellows;
using testing::TempDir;
namespace fs = std::filesystem;
using Json = nlohmann::ordered_json;

Json read_manifest(const fs::path& session) { return Json::parse(testing::read_text(session / "manifest.json")); }
void write_manifest(const fs::path& session, const Json& json) {
  testing::write_text(session / "manifest.json", json.dump(2));
}

/// One line on stderr, starting "bellows: ", containing `expected`, with exit status 2.
void expect_refused(const ProcessResult& result, const std::string& expected) {
  EXPECT_FALSE(result.hung) << "hung, killed by the guard";
  EXPECT_EQ(result.exit_code, 2) << result.err;
  EXPECT_EQ(std::count(result.err.begin(), result.err.end(), '\n'), 1) << result.err;
  EXPECT_EQ(result.err.rfind("bellows: ", 0), 0u) << result.err;
  EXPECT_NE(result.err.find(expected), std::string::npos) << result.err;
}

/// Every command that reads a session refuses it, and a refused resume leaves the session as it was.
void expect_every_command_refuses(const fs::path& session, const std::string& expected) {
  expect_refused(run_bellows({"sessions", "show", session.string()}), expected);
  expect_refused(run_bellows({"sessions", "show", "--json", session.string()}), expected);
  expect_refused(
      run_bellows({"sessions", "export", session.string(), "--output", (session.parent_path() / "x.csv").string()}),
      expected);
  const std::string manifest = fs::is_regular_file(fs::symlink_status(session / "manifest.json"))
                                   ? testing::read_text(session / "manifest.json")
                                   : "";
  expect_refused(run_bellows({"run", "--resume", session.string(), "--iterations", "1"}), expected);
  if (!manifest.empty()) {
    EXPECT_EQ(testing::read_text(session / "manifest.json"), manifest);
  }
}

class HostileSession : public ::testing::Test {
 protected:
  void SetUp() override {
    save_session(testing::simulate_session(2), session_);
    fs::create_directories(outside_);
    testing::write_text(victim_, "precious: the first line of a file outside the session\n");
  }
  /// The files outside the session, and their contents: a test checks them unchanged.
  std::vector<std::pair<fs::path, std::string>> outside_files() const {
    std::vector<std::pair<fs::path, std::string>> files;
    for (const auto& entry : fs::recursive_directory_iterator(outside_)) {
      if (entry.is_regular_file()) files.emplace_back(entry.path(), testing::read_text(entry.path()));
    }
    std::sort(files.begin(), files.end());
    return files;
  }
  TempDir dir_;
  fs::path session_ = dir_ / "s";
  fs::path outside_ = dir_ / "outside";
  fs::path victim_ = outside_ / "victim";
};

TEST_F(HostileSession, ASymlinkedLockIsRefusedAndItsTargetUntouched) {
  fs::remove(session_ / "lock");
  fs::create_symlink(victim_, session_ / "lock");
  const auto before = outside_files();
  expect_refused(run_bellows({"run", "--resume", session_.string(), "--iterations", "1"}),
                 "session " + session_.string() + ": lock is a symbolic link");
  EXPECT_EQ(outside_files(), before);
}

TEST_F(HostileSession, AHardLinkedLockIsRefused) {
  fs::remove(session_ / "lock");
  fs::create_hard_link(victim_, session_ / "lock");
  const auto before = outside_files();
  expect_refused(run_bellows({"run", "--resume", session_.string(), "--iterations", "1"}), "lock has 2 hard links");
  EXPECT_EQ(outside_files(), before);
}

TEST_F(HostileSession, ASymlinkedIterationsFolderIsRefusedAndNothingWrittenOrDeletedThere) {
  // The target holds what a resume would delete (a "leftover" of iteration 2) and overwrite.
  fs::rename(session_ / "iterations", outside_ / "iterations");
  fs::create_directory_symlink(outside_ / "iterations", session_ / "iterations");
  testing::write_text(outside_ / "iterations" / "iteration_0002.csv", "not a leftover\n");
  const auto before = outside_files();
  expect_every_command_refuses(session_, "session " + session_.string() + ": iterations is a symbolic link");
  EXPECT_EQ(outside_files(), before);
}

TEST_F(HostileSession, ASymlinkedFaultsFolderIsRefusedAndNothingDeletedThere) {
  fs::create_directories(outside_ / "faults");
  testing::write_text(outside_ / "faults" / "blackbox_0000.csv", "not a leftover\n");
  fs::create_directory_symlink(outside_ / "faults", session_ / "faults");
  const auto before = outside_files();
  expect_every_command_refuses(session_, "faults is a symbolic link");
  EXPECT_EQ(outside_files(), before);
}

TEST_F(HostileSession, SymlinkedFilesAreRefusedWithoutQuotingTheirTargets) {
  for (const std::string file : {"trajectory.csv", "manifest.json", "iterations/telemetry_0001.csv"}) {
    SCOPED_TRACE(file);
    TempDir other;
    const fs::path session = other / "s";
    save_session(testing::simulate_session(2), session);
    fs::rename(session / file, other / "real");
    fs::create_symlink(victim_, session / file);
    expect_every_command_refuses(session, file + " is a symbolic link");
    EXPECT_EQ(run_bellows({"sessions", "show", session.string()}).err.find("precious"), std::string::npos);
  }
}

TEST_F(HostileSession, FifosAreRefusedWithoutHanging) {
  for (const std::string file : {"manifest.json", "trajectory.csv", "iterations/iteration_0001.csv"}) {
    SCOPED_TRACE(file);
    TempDir other;
    const fs::path session = other / "s";
    save_session(testing::simulate_session(2), session);
    fs::remove(session / file);
    ASSERT_EQ(::mkfifo((session / file).c_str(), 0644), 0);
    expect_every_command_refuses(session, file + " is a FIFO, not a regular file");
  }
}

TEST_F(HostileSession, AManifestLargerThanItsFormatAllowsIsRefusedUnread) {
  fs::resize_file(session_ / "manifest.json", session_layout::kMostManifestBytes + 1);  // sparse: no disk used
  expect_every_command_refuses(session_, "manifest.json is " + std::to_string(session_layout::kMostManifestBytes + 1) +
                                             " bytes, more than the " +
                                             std::to_string(session_layout::kMostManifestBytes));
}

TEST_F(HostileSession, AnOversizedCsvIsRefusedUnread) {
  fs::resize_file(session_ / "iterations" / "telemetry_0000.csv", std::uintmax_t{1} << 30);
  expect_every_command_refuses(session_, "iterations/telemetry_0000.csv is 1073741824 bytes, more than the");
}

TEST_F(HostileSession, ListingShowsTheGoodSessionsAndALineForEachBadOne) {
  const fs::path data = dir_ / "data";
  fs::create_directories(data);
  save_session(testing::simulate_session(1, "good"), data / "good");
  save_session(testing::simulate_session(1), data / "zero");
  fs::remove(data / "zero" / "manifest.json");
  fs::create_symlink("/dev/zero", data / "zero" / "manifest.json");
  save_session(testing::simulate_session(1), data / "fifo");
  fs::remove(data / "fifo" / "manifest.json");
  ASSERT_EQ(::mkfifo((data / "fifo" / "manifest.json").c_str(), 0644), 0);
  save_session(testing::simulate_session(1), data / "huge");
  fs::resize_file(data / "huge" / "manifest.json", std::uintmax_t{1} << 32);
  fs::create_directory_symlink(session_, data / "linked");

  const ProcessResult list = run_bellows({"sessions", "list", "--data-dir", data.string(), "--json"});
  EXPECT_FALSE(list.hung);
  ASSERT_EQ(list.exit_code, 0) << list.err;
  const Json listed = Json::parse(list.out);
  ASSERT_EQ(listed.size(), 5u) << list.out;
  int good = 0;
  for (const Json& entry : listed) good += entry.contains("error") ? 0 : 1;
  EXPECT_EQ(good, 1);
  EXPECT_EQ(std::count(list.err.begin(), list.err.end(), '\n'), 4) << list.err;
  for (const std::string expected : {"zero: manifest.json is a symbolic link", "fifo: manifest.json is a FIFO",
                                     "huge: manifest.json is 4294967296 bytes", "linked: linked is a symbolic link"}) {
    EXPECT_NE(list.err.find(expected), std::string::npos) << expected << "\n" << list.err;
  }
  const ProcessResult table = run_bellows({"sessions", "list", "--data-dir", data.string()});
  EXPECT_EQ(table.exit_code, 0);
  EXPECT_NE(table.out.find("\ngood "), std::string::npos) << table.out;
}

TEST_F(HostileSession, AnEditedTrajectoryIsRefusedByItsDigest) {
  // One angle changed to 80 deg: a valid trajectory, but not the one the iterations ran.
  std::string text = testing::read_text(session_ / "trajectory.csv");
  const std::size_t line = text.find('\n', text.find('\n', text.size() / 2) + 1);
  const std::size_t comma = text.find(',', line);
  text.replace(comma + 1, text.find('\n', comma) - comma - 1, "80");
  testing::write_text(session_ / "trajectory.csv", text);
  expect_every_command_refuses(
      session_, "session " + session_.string() + ": trajectory.csv was changed after it was saved: its SHA-256 digest");
}

TEST_F(HostileSession, EveryListedFileHasADigestThatShowVerifies) {
  const Json manifest = read_manifest(session_);
  EXPECT_EQ(manifest["trajectory"]["sha256"], sha256_hex(testing::read_text(session_ / "trajectory.csv")));
  EXPECT_EQ(manifest["iterations"][1]["samples_sha256"],
            sha256_hex(testing::read_text(session_ / "iterations" / "iteration_0001.csv")));
  const ProcessResult shown = run_bellows({"sessions", "show", session_.string()});
  ASSERT_EQ(shown.exit_code, 0) << shown.err;
  EXPECT_NE(shown.out.find("integrity    verified: the 5 files match their SHA-256 digests"), std::string::npos)
      << shown.out;
}

TEST_F(HostileSession, ASessionSavedBeforeDigestsOpensAsUnverified) {
  // A session as `bellows run` saves it, with its digests then taken out, as an older bellows wrote it.
  testing::write_short_run_files(dir_.path());
  const fs::path session = dir_ / "data" / "old";
  const ProcessResult first =
      run_bellows({"run", "--trajectory", (dir_ / "short.csv").string(), "--config", (dir_ / "short.toml").string(),
                   "--iterations", "1", "--data-dir", (dir_ / "data").string(), "--name", "old"});
  ASSERT_EQ(first.exit_code, 0) << first.err;
  Json manifest = read_manifest(session);
  manifest["trajectory"].erase("sha256");
  for (Json& iteration : manifest["iterations"]) {
    iteration.erase("samples_sha256");
    iteration.erase("telemetry_sha256");
  }
  write_manifest(session, manifest);
  const ProcessResult shown = run_bellows({"sessions", "show", session.string()});
  ASSERT_EQ(shown.exit_code, 0) << shown.err;
  EXPECT_NE(shown.out.find("integrity    unverified: 5 files have no digest"), std::string::npos) << shown.out;
  const Json json = Json::parse(run_bellows({"sessions", "show", "--json", session.string()}).out);
  EXPECT_EQ(json["integrity"]["unverified_files"], 5);
  // A resume continues it; the iteration it adds has digests.
  const ProcessResult resumed = run_bellows({"run", "--resume", session.string(), "--iterations", "1"});
  ASSERT_EQ(resumed.exit_code, 0) << resumed.err;
  EXPECT_TRUE(read_manifest(session)["iterations"][2].contains("samples_sha256"));
  EXPECT_FALSE(read_manifest(session)["iterations"][1].contains("samples_sha256"));
}

TEST_F(HostileSession, AMalformedDigestIsRefused) {
  Json manifest = read_manifest(session_);
  manifest["iterations"][0]["telemetry_sha256"] = "../../etc/passwd";
  write_manifest(session_, manifest);
  expect_every_command_refuses(session_, "/iterations/0/telemetry_sha256: expected a SHA-256 digest");
}

/// True when `text` holds a byte a terminal would act on (C0 but newline, DEL, C1 as UTF-8).
bool has_control_bytes(const std::string& text) {
  for (std::size_t i = 0; i < text.size(); ++i) {
    const auto c = static_cast<unsigned char>(text[i]);
    if ((c < 0x20 && c != '\n') || c == 0x7f) return true;
    if (c == 0xc2 && i + 1 < text.size() && static_cast<unsigned char>(text[i + 1]) >= 0x80 &&
        static_cast<unsigned char>(text[i + 1]) <= 0x9f) {
      return true;
    }
  }
  return false;
}

TEST_F(HostileSession, TextFromASessionReachesTheTerminalEscapedAndShortened) {
  const fs::path data = dir_ / "data";
  const std::string attack =
      "\x1b]0;owned\x07\x1b[2J\xc2\x9b"
      "31m\xe2\x80\xae";
  const fs::path session = data / ("evil" + attack);
  fs::create_directories(data);
  save_session(testing::simulate_session(1), session);
  Json manifest = read_manifest(session);
  manifest["name"] = "name" + attack;
  manifest["device_info"]["note"] = attack;
  manifest["events"][0]["message"] = "message" + attack + std::string(10 << 20, 'x');  // a 10 MB field
  manifest["events"][0]["kind"] = "kind" + attack;
  std::string many_lines;  // a console-log event is shown a line per row: a million rows is too many
  for (int i = 0; i < 1000000; ++i) many_lines += "12:00:00 operator: line\n";
  manifest["events"].push_back(
      {{"time_utc", "2024-05-01T12:00:00.000Z"}, {"iteration", 0}, {"kind", "console-log"}, {"message", many_lines}});
  write_manifest(session, manifest);

  const ProcessResult shown = run_bellows({"sessions", "show", session.string()});
  ASSERT_EQ(shown.exit_code, 0) << shown.err;
  EXPECT_FALSE(has_control_bytes(shown.out)) << shown.out.substr(0, 2000);
  EXPECT_LT(shown.out.size(), 20000u);
  EXPECT_NE(shown.out.find("name         name\\e]0;owned\\x07\\e[2J\\u{009b}31m\\u{202e}"), std::string::npos)
      << shown.out.substr(0, 2000);
  EXPECT_NE(shown.out.find("bytes)"), std::string::npos);  // the 10 MB message, cut
  for (const auto& args : {std::vector<std::string>{"sessions", "show", "--json", session.string()},
                           std::vector<std::string>{"sessions", "list", "--data-dir", data.string()},
                           std::vector<std::string>{"sessions", "list", "--data-dir", data.string(), "--json"}}) {
    const ProcessResult result = run_bellows(args);
    EXPECT_EQ(result.exit_code, 0) << result.err;
    EXPECT_FALSE(has_control_bytes(result.out)) << args.back();
  }
  // A bad line in a CSV, quoted in an error, is escaped and cut too.
  std::string trajectory = testing::read_text(session / "trajectory.csv");
  trajectory.insert(trajectory.find('\n') + 1, "0," + attack + std::string(10 << 20, '9') + "\n");
  testing::write_text(session / "trajectory.csv", trajectory);
  const ProcessResult refused = run_bellows({"sessions", "show", session.string()});
  EXPECT_EQ(refused.exit_code, 2);
  EXPECT_FALSE(has_control_bytes(refused.err)) << refused.err.substr(0, 2000);
  EXPECT_LT(refused.err.size(), 5000u);
}

// A manifest nested 100 000 levels deep (a few hundred kB) parses, but copying it recursed once a
// level and overflowed the stack: `sessions show` and `list` died with SIGSEGV, and the console's
// browser would have taken the console with it. Refused in one line naming the file; the listing
// goes on past it.
TEST_F(HostileSession, AManifestNestedTooDeepIsRefusedNotACrash) {
  const fs::path data = dir_ / "data";
  save_session(testing::simulate_session(1), data / "deep");
  save_session(testing::simulate_session(1), data / "fine");
  Json manifest = read_manifest(data / "deep");
  manifest["device_info"]["x"] = "DEEP";
  write_manifest(data / "deep", manifest);
  std::string text = testing::read_text(data / "deep" / "manifest.json");
  text.replace(text.find("\"DEEP\""), 6, std::string(100000, '[') + std::string(100000, ']'));
  testing::write_text(data / "deep" / "manifest.json", text);

  expect_refused(run_bellows({"sessions", "show", (data / "deep").string()}), "nested more than 64 levels deep");
  const ProcessResult listed = run_bellows({"sessions", "list", "--data-dir", data.string()});
  EXPECT_EQ(listed.exit_code, 0) << listed.err;
  EXPECT_NE(listed.out.find("fine"), std::string::npos) << listed.out;
}

/// `text` with every line end CR LF and a byte order mark in front.
std::string windows_text(const std::string& text, bool byte_order_mark) {
  std::string out = byte_order_mark ? "\xef\xbb\xbf" : "";
  for (char c : text) {
    if (c == '\n') out += '\r';
    out += c;
  }
  return out;
}

TEST_F(HostileSession, CrLfCsvsAndAByteOrderMarkAreAccepted) {
  Json manifest = read_manifest(session_);
  const auto convert = [&](const std::string& relative, bool byte_order_mark) {
    const std::string text = windows_text(testing::read_text(session_ / relative), byte_order_mark);
    testing::write_text(session_ / relative, text);
    return sha256_hex(text);  // as a tool that rewrote the files would also record
  };
  manifest["trajectory"]["sha256"] = convert("trajectory.csv", true);
  manifest["iterations"][0]["samples_sha256"] = convert(session_layout::samples_file(0), false);
  manifest["iterations"][0]["telemetry_sha256"] = convert(session_layout::telemetry_file(0), true);
  write_manifest(session_, manifest);
  const ProcessResult shown = run_bellows({"sessions", "show", session_.string()});
  EXPECT_EQ(shown.exit_code, 0) << shown.err;

  // And a trajectory file for `run` saved by a spreadsheet.
  testing::write_short_run_files(dir_.path());
  testing::write_text(dir_ / "short.csv", windows_text(testing::read_text(dir_ / "short.csv"), true));
  const ProcessResult run = run_bellows({"run", "--trajectory", (dir_ / "short.csv").string(), "--config",
                                         (dir_ / "short.toml").string(), "--iterations", "0", "--no-save"});
  EXPECT_EQ(run.exit_code, 0) << run.err;
}

/// Runs bellows with its standard output on /dev/full; returns the exit status and stderr.
ProcessResult run_into_full_disk(const TempDir& dir, const std::string& args) {
  const fs::path err = dir / "stderr.txt";
  const int status =
      std::system(("'" + std::string(BELLOWS_BINARY) + "' " + args + " >/dev/full 2>'" + err.string() + "'").c_str());
  ProcessResult result;
  result.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  result.err = testing::read_text(err);
  return result;
}

TEST_F(HostileSession, AReportThatCannotBeWrittenIsAnErrorNotASilentSuccess) {
  ASSERT_TRUE(fs::exists("/dev/full"));
  for (const std::string& args :
       {"sessions show --json '" + session_.string() + "'", "sessions show '" + session_.string() + "'",
        std::string("run --json --no-save --iterations 0")}) {
    SCOPED_TRACE(args);
    const ProcessResult result = run_into_full_disk(dir_, args);
    EXPECT_EQ(result.exit_code, 4);
    // After the progress lines `run --json` prints on stderr: one line, last.
    const std::string line = "bellows: cannot write to standard output: No space left on device\n";
    EXPECT_EQ(result.err.substr(result.err.size() - std::min(result.err.size(), line.size())), line) << result.err;
    EXPECT_EQ(result.err.find("bellows:"), result.err.size() - line.size()) << result.err;
  }
}

TEST(HostileInput, AnEmptySessionNameIsRefusedNotIgnored) {
  TempDir dir;
  const ProcessResult result =
      run_bellows({"run", "--iterations", "0", "--data-dir", (dir / "data").string(), "--name", ""});
  expect_refused(result, "the session name must not be empty");
  EXPECT_FALSE(fs::exists(dir / "data"));
  expect_refused(
      run_bellows({"run", "--iterations", "0", "--data-dir", (dir / "data").string(), "--name", "a\x1b[2Jb"}),
      "session name 'a\\e[2Jb' must be a plain directory name");
}

TEST(HostileInput, AConfigOrTrajectoryThatIsNotARegularFileIsRefusedWithoutHanging) {
  TempDir dir;
  ASSERT_EQ(::mkfifo((dir / "fifo").c_str(), 0644), 0);
  expect_refused(run_bellows({"run", "--no-save", "--config", dir.path().string()}),
                 "config " + dir.path().string() + " is a directory, not a regular file");
  expect_refused(run_bellows({"config", "--config", (dir / "fifo").string()}),
                 "config " + (dir / "fifo").string() + " is a FIFO, not a regular file");
  expect_refused(run_bellows({"run", "--no-save", "--config", "/dev/zero"}), "config /dev/zero is a character device");
  expect_refused(run_bellows({"run", "--no-save", "--trajectory", (dir / "fifo").string()}),
                 "trajectory " + (dir / "fifo").string() + " is a FIFO, not a regular file");
}

}  // namespace
}  // namespace bellows
