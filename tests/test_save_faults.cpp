// Fault injection over every system call of a save (issue 24). The LD_PRELOAD shim
// (tests/fault/fault_injection_shim.cpp) kills the process (SIGKILL) or fails one call (ENOSPC) at
// the k-th write/rename/fsync/fsync of a directory; each sweep first counts the calls of a clean
// run, then runs every k and checks the verdict:
//  - the console's per-trial save (tests/fault/console_save_driver.cpp, no terminal): killed at k,
//    the session loads with every trial completed before that save (and at most the one it was
//    saving), says what it dropped, and a writer continues it; failed at k, the console says which
//    trial is not on disk and exits 4 after the confirmation that names it;
//  - every writer outside the store (export, rename's manifest, trajectories --output, plot's
//    script): killed at k, each output is absent or complete, never partial, and nothing else was
//    written; failed at k, one line, a non-zero exit, no output left half-written, no temporary.
#include <sys/stat.h>

#include <cstdio>
#include <fstream>
#include <set>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "session_test_support.hpp"
#include "sessions/atomic_file.hpp"
#include "sessions/session_store.hpp"
#include "sessions/session_writer.hpp"
#include "tests/test_support.hpp"

namespace bellows {
namespace {

namespace fs = std::filesystem;
using testing::TempDir;

const std::string kShim = BELLOWS_FAULT_SHIM;
const std::string kDriver = CONSOLE_SAVE_DRIVER;

std::string quoted(const std::string& text) { return "'" + text + "'"; }

/// `command` (a shell line) under the shim: `mode` "count" (counts into `count_file`), "kill" or
/// "enospc" at call `k`.
testing::ProcessResult run_faulted(const std::string& command, const std::string& mode, int k,
                                   const fs::path& count_file = {}) {
  std::string env = "LD_PRELOAD=" + quoted(kShim) + " ";
  if (mode == "count") {
    env += "BELLOWS_FAULT_COUNT=" + quoted(count_file.string()) + " ";
  } else {
    env += "BELLOWS_FAULT_MODE=" + mode + " BELLOWS_FAULT_AT=" + std::to_string(k) + " ";
  }
  return testing::run_process(env + command);
}

int counted_calls(const std::string& command, const fs::path& scratch) {
  const fs::path count_file = scratch / "count.txt";
  const testing::ProcessResult clean = run_faulted(command, "count", 0, count_file);
  EXPECT_EQ(clean.exit_code, 0) << command << "\n" << clean.out << clean.err;
  std::ifstream in(count_file);
  int count = 0;
  in >> count;
  return count;
}

std::vector<fs::path> entries(const fs::path& directory) {
  std::vector<fs::path> out;
  std::error_code error;
  for (const auto& entry : fs::directory_iterator(directory, error)) out.push_back(entry.path());
  return out;
}

std::string line_of(const std::string& out, const std::string& key) {
  const std::size_t at = out.find(key + ": ");
  if (at == std::string::npos) return "";
  const std::size_t end = out.find('\n', at);
  return out.substr(at + key.size() + 2, end - at - key.size() - 2);
}

class SaveFaults : public ::testing::Test {
 protected:
  void SetUp() override {
    if (testing::kSanitized) GTEST_SKIP() << "the LD_PRELOAD shim and the sanitizers' runtimes do not mix";
  }
};

// --- the console's per-trial save ------------------------------------------------------------

/// The session the driver made in `data` (the only directory there).
fs::path session_in(const fs::path& data) {
  for (const fs::path& p : entries(data)) {
    if (fs::is_directory(p) && p.filename().string().front() != '.') return p;
  }
  return {};
}

TEST_F(SaveFaults, TheConsolesSaveKilledAtEveryCallLeavesTheLastCommittedState) {
  TempDir scratch;
  const std::string command = quoted(kDriver) + " " + quoted((scratch / "clean").string());
  fs::create_directory(scratch / "clean");
  const int calls = counted_calls(command, scratch.path());
  // Two saves (the learned correction of iteration 1, then iteration 2): files, fsyncs, renames.
  ASSERT_GE(calls, 12) << "the armed window counted too few calls";
  const Session clean = load_session(session_in(scratch / "clean"));
  ASSERT_EQ(clean.iterations.size(), 3u);
  int dropped_reported = 0, at_two = 0, at_three = 0;
  for (int k = 1; k <= calls; ++k) {
    SCOPED_TRACE("kill at call " + std::to_string(k) + " of " + std::to_string(calls));
    const fs::path data = scratch / ("k" + std::to_string(k));
    fs::create_directory(data);
    const testing::ProcessResult killed = run_faulted(quoted(kDriver) + " " + quoted(data.string()), "kill", k);
    ASSERT_EQ(killed.exit_code, 128 + SIGKILL) << killed.out << killed.err;
    const fs::path session = session_in(data);
    ASSERT_FALSE(session.empty());
    // The operator's view: `sessions show` loads it, naming what the interrupted save dropped.
    const testing::ProcessResult show = testing::run_bellows({"sessions", "show", session.string(), "--json"});
    ASSERT_EQ(show.exit_code, 0) << show.err;
    const Session loaded = load_session(session);
    const std::size_t n = loaded.iterations.size();
    ASSERT_TRUE(n == 2 || n == 3) << n;
    (n == 2 ? at_two : at_three)++;
    if (!loaded.dropped.empty()) {
      ++dropped_reported;
      EXPECT_NE(show.err.find("dropped"), std::string::npos) << show.err;
      EXPECT_NE(show.err.find(loaded.dropped), std::string::npos) << show.err;
    }
    // Every trial completed before that save, exactly as the clean run saved them.
    for (std::size_t i = 0; i < n; ++i) {
      EXPECT_EQ(loaded.iterations[i].record.joint_samples(0).angle_rad, clean.iterations[i].record.joint_samples(0).angle_rad) << i;
      EXPECT_EQ(loaded.iterations[i].record.joint_samples(0).u_ilc_bar, clean.iterations[i].record.joint_samples(0).u_ilc_bar) << i;
    }
    // Iteration 1's correction is the one learned from it (committed) or the one before (not yet):
    // never anything else; with iteration 2 listed, it is what iteration 2 ran with.
    const Eigen::MatrixXd next1 = loaded.iterations[1].next_corrections_bar();
    const Eigen::MatrixXd ran2 = clean.iterations[2].record.joint_samples(0).u_ilc_bar.head(clean.trajectory.learning_samples());
    if (n == 3) {
      EXPECT_TRUE(next1.col(0) == ran2.col(0)) << "iteration 2 listed with another correction than it ran";
    }
    // Continuing it (a resume, the console's open): the writer takes it as committed, removes what
    // was dropped, and the session loads the same without a word.
    {
      Session reopened;
      SessionWriter writer = SessionWriter::open(session, "test", reopened);
      EXPECT_EQ(reopened.iterations.size(), n);
    }
    const Session after = load_session(session);
    EXPECT_EQ(after.iterations.size(), n);
    EXPECT_EQ(after.dropped, "");
  }
  // The sweep crossed both outcomes and the loader named what it dropped.
  EXPECT_GT(at_two, 0);
  EXPECT_GT(at_three, 0);
  EXPECT_GT(dropped_reported, 0);
  std::printf("console save: %d calls swept (kill): %d left 2 iterations, %d left 3, %d reported a drop\n", calls, at_two,
              at_three, dropped_reported);
}

TEST_F(SaveFaults, TheConsolesSaveFailingAtEveryCallIsReportedAndExitsNonZero) {
  TempDir scratch;
  fs::create_directory(scratch / "clean");
  const int calls = counted_calls(quoted(kDriver) + " " + quoted((scratch / "clean").string()), scratch.path());
  ASSERT_GE(calls, 12);
  for (int k = 1; k <= calls; ++k) {
    SCOPED_TRACE("ENOSPC at call " + std::to_string(k) + " of " + std::to_string(calls));
    const fs::path data = scratch / ("k" + std::to_string(k));
    fs::create_directory(data);
    const testing::ProcessResult failed = run_faulted(quoted(kDriver) + " " + quoted(data.string()), "enospc", k);
    // Never reported as saved: the operator reads which trial is not on disk, the confirmation names
    // it, and the console exits 4.
    EXPECT_EQ(failed.exit_code, 4) << failed.out << failed.err;
    const std::string unsaved = line_of(failed.out, "unsaved");
    EXPECT_NE(unsaved.find("iteration"), std::string::npos) << failed.out;
    EXPECT_NE(unsaved.find("not saved"), std::string::npos) << failed.out;
    const std::string failure = line_of(failed.out, "failure");  // the log line, also the status until a stop replaces it
    EXPECT_NE(failure.find("No space left on device"), std::string::npos) << failed.out;
    EXPECT_NE(failure.find(unsaved), std::string::npos) << failed.out;
    EXPECT_NE(line_of(failed.out, "confirmation").find(unsaved), std::string::npos) << failed.out;
    EXPECT_EQ(line_of(failed.out, "quit"), "yes");
    // What is on disk is a committed state: it loads.
    const fs::path session = session_in(data);
    ASSERT_FALSE(session.empty());
    const testing::ProcessResult show = testing::run_bellows({"sessions", "show", session.string()});
    EXPECT_EQ(show.exit_code, 0) << show.err;
  }
  std::printf("console save: %d calls swept (ENOSPC), each reported unsaved, exit 4\n", calls);
}

// --- the writers outside the session store ----------------------------------------------------

/// A small session to write from (made once, by bellows itself).
const fs::path& small_session() {
  static const fs::path made = [] {
    const fs::path data = testing::make_temp_dir("bellows-save-faults");
    const testing::ProcessResult run =
        testing::run_bellows({"run", "--iterations", "2", "--data-dir", data.string(), "--name", "s"});
    EXPECT_EQ(run.exit_code, 0) << run.err;
    return data / "s";
  }();
  return made;
}

struct Writer {
  std::string name;
  /// The shell command writing into `out` (a fresh folder); the files it writes there.
  std::function<std::string(const fs::path& out)> command;
  std::vector<std::string> outputs;
};

/// Each output in `out` is absent or byte-identical to the clean run's; nothing else is there but
/// hidden temporaries (a kill) or nothing at all (a failure, which cleans up).
void expect_whole_outputs(const fs::path& out, const fs::path& clean, const Writer& writer, bool temporaries_allowed) {
  std::set<std::string> expected(writer.outputs.begin(), writer.outputs.end());
  for (const fs::path& p : entries(out)) {
    const std::string name = p.filename().string();
    if (is_temporary_file_name(name)) {
      EXPECT_TRUE(temporaries_allowed) << "a temporary left behind after a failure: " << name;
      continue;
    }
    ASSERT_TRUE(expected.count(name)) << "unexpected " << name;
    EXPECT_FALSE(fs::is_symlink(p)) << name;
    EXPECT_EQ(testing::read_text(p), testing::read_text(clean / name)) << name << " is partial";
  }
}

TEST_F(SaveFaults, EveryWriterKilledOrFailedAtEveryCallLeavesWholeFilesOrNone) {
  const fs::path session = small_session();
  ASSERT_TRUE(fs::is_directory(session));
  const std::vector<Writer> writers = {
      {"sessions export",
       [&](const fs::path& out) {
         return quoted(testing::kBellows) + " sessions export " + quoted(session.string()) + " --output " +
                quoted((out / "e.csv").string());
       },
       {"e.csv", "e_telemetry.csv", "e_summary.csv"}},
      {"trajectories --output",
       [](const fs::path& out) { return quoted(testing::kBellows) + " trajectories paper --output " + quoted((out / "t.csv").string()); },
       {"t.csv"}},
      {"sessions rename (the manifest)",
       [&](const fs::path& out) {
         const testing::ProcessResult copy = testing::run_process("cp -r " + quoted(session.string()) + " " + quoted((out / "a").string()));
         EXPECT_EQ(copy.exit_code, 0);
         return quoted(testing::kBellows) + " sessions rename " + quoted((out / "a").string()) + " b";
       },
       {"a", "b"}},
  };
  for (const Writer& writer : writers) {
    SCOPED_TRACE(writer.name);
    TempDir scratch;
    fs::create_directory(scratch / "clean");
    const int calls = counted_calls(writer.command(scratch / "clean"), scratch.path());
    ASSERT_GE(calls, 3) << "write, fsync, rename at least";
    int killed_whole = 0;
    for (const std::string mode : {"kill", "enospc"}) {
      for (int k = 1; k <= calls; ++k) {
        SCOPED_TRACE(mode + " at call " + std::to_string(k) + " of " + std::to_string(calls));
        const fs::path out = scratch / (mode + std::to_string(k));
        fs::create_directory(out);
        const std::string command = writer.command(out);
        const testing::ProcessResult result = run_faulted(command, mode, k);
        if (mode == std::string("kill")) {
          EXPECT_EQ(result.exit_code, 128 + SIGKILL) << result.err;
        } else {
          EXPECT_NE(result.exit_code, 0) << "a failed write reported as done";
          EXPECT_NE(result.err.find("No space left on device"), std::string::npos) << result.err;
        }
        if (writer.name.rfind("sessions rename", 0) == 0) {
          // The session is a whole session under one of its names, loading, named in its manifest
          // as its directory or still by its old name (the rename is directory first).
          const bool at_b = fs::is_directory(out / "b");
          const fs::path where = at_b ? out / "b" : out / "a";
          ASSERT_TRUE(fs::is_directory(where));
          EXPECT_FALSE(fs::is_symlink(where / "manifest.json"));
          const Session loaded = load_session(where);
          EXPECT_EQ(loaded.iterations.size(), 3u);  // run --iterations 2: iterations 0..2
          if (mode == std::string("enospc")) {
            for (const fs::path& p : entries(where)) EXPECT_FALSE(is_temporary_file_name(p.filename().string())) << p;
          }
          continue;
        }
        expect_whole_outputs(out, scratch / "clean", writer, mode == std::string("kill"));
        if (mode == std::string("kill")) ++killed_whole;
      }
    }
    std::printf("%s: %d calls swept, kill and ENOSPC at each\n", writer.name.c_str(), calls);
  }
}

// --- symbolic links planted where a writer writes -----------------------------------------------

TEST_F(SaveFaults, LinksPlantedAtTheOldTemporaryNamesWriteNothingOutside) {
  const fs::path session = small_session();
  TempDir dir;
  const fs::path victim = dir / "victim";
  testing::write_text(victim, "precious\n");
  const testing::ProcessResult copy = testing::run_process("cp -r " + quoted(session.string()) + " " + quoted((dir / "S").string()));
  ASSERT_EQ(copy.exit_code, 0);
  // sessions rename: the old temporary name was .manifest.json.tmp-<pid>; $$ is the pid bellows gets.
  const std::string b = quoted(testing::kBellows);
  const testing::ProcessResult rename = testing::run_process(
      "bash -c " + quoted("ln -s " + victim.string() + " " + (dir / "S").string() + "/.manifest.json.tmp-$$; exec " +
                          testing::kBellows + " sessions rename " + (dir / "S").string() + " S2"));
  EXPECT_EQ(rename.exit_code, 0) << rename.err;
  EXPECT_EQ(testing::read_text(victim), "precious\n");
  EXPECT_FALSE(fs::is_symlink(dir / "S2" / "manifest.json"));
  EXPECT_TRUE(fs::is_regular_file(dir / "S2" / "manifest.json"));
  EXPECT_EQ(load_session(dir / "S2").manifest.name, "S2");
  // sessions export, trajectories --output, plot: the same at their old names.
  const fs::path out = dir / "out";
  fs::create_directory(out);
  for (const auto& [planted, command] : std::vector<std::pair<std::string, std::string>>{
           {".e.csv.tmp-$$", "sessions export " + (dir / "S2").string() + " --output " + (out / "e.csv").string()},
           {".t.csv.tmp-$$", "trajectories paper --output " + (out / "t.csv").string()},
       }) {
    SCOPED_TRACE(command);
    const testing::ProcessResult result = testing::run_process(
        "bash -c " + quoted("ln -sf " + victim.string() + " " + out.string() + "/" + planted + "; exec " + testing::kBellows + " " + command));
    EXPECT_EQ(result.exit_code, 0) << result.err;
    EXPECT_EQ(testing::read_text(victim), "precious\n");
  }
  EXPECT_FALSE(fs::is_symlink(out / "e.csv"));
  EXPECT_FALSE(fs::is_symlink(out / "t.csv"));
}

TEST_F(SaveFaults, AnOutputThatIsALinkOrExistsIsRefusedWithoutForceAndReplacedWithIt) {
  TempDir dir;
  const fs::path victim = dir / "victim";
  testing::write_text(victim, "precious\n");
  const fs::path existing = dir / "existing.csv";
  testing::write_text(existing, "mine\n");
  const testing::ProcessResult refused = testing::run_bellows({"trajectories", "steps", "--output", existing.string()});
  EXPECT_EQ(refused.exit_code, 2) << refused.err;
  EXPECT_NE(refused.err.find("exists already (--force replaces it)"), std::string::npos) << refused.err;
  EXPECT_EQ(testing::read_text(existing), "mine\n");
  const testing::ProcessResult forced = testing::run_bellows({"trajectories", "steps", "--output", existing.string(), "--force"});
  EXPECT_EQ(forced.exit_code, 0) << forced.err;
  EXPECT_NE(testing::read_text(existing), "mine\n");
  // A link at the output: refused without --force; with it, the link is replaced, never followed.
  fs::create_symlink(victim, dir / "link.csv");
  EXPECT_EQ(testing::run_bellows({"trajectories", "steps", "--output", (dir / "link.csv").string()}).exit_code, 2);
  EXPECT_EQ(testing::run_bellows({"trajectories", "steps", "--output", (dir / "link.csv").string(), "--force"}).exit_code, 0);
  EXPECT_FALSE(fs::is_symlink(dir / "link.csv"));
  EXPECT_EQ(testing::read_text(victim), "precious\n");
  // The LCM log: a dangling link at its name is refused, and nothing is created through it.
  fs::create_symlink(dir / "created-through-link", dir / "log.lcmlog");
  const testing::ProcessResult log = testing::run_bellows({"run", "--iterations", "1", "--no-save", "--lcm-log", (dir / "log.lcmlog").string()});
  EXPECT_EQ(log.exit_code, 2) << log.err;
  EXPECT_FALSE(fs::exists(dir / "created-through-link"));
}

// --- sessions rm ---------------------------------------------------------------------------------

TEST_F(SaveFaults, SessionsRmRemovesOnlyABellowsSession) {
  TempDir dir;
  // A folder with a manifest.json that is not a session's.
  fs::create_directories(dir / "w" / "src");
  testing::write_text(dir / "w" / "manifest.json", "{\"name\":\"app\"}\n");
  testing::write_text(dir / "w" / "src" / "main.c", "int main;\n");
  const testing::ProcessResult other = testing::run_bellows({"sessions", "rm", (dir / "w").string(), "--yes"});
  EXPECT_EQ(other.exit_code, 2) << other.err;
  EXPECT_NE(other.err.find("not a bellows session"), std::string::npos) << other.err;
  EXPECT_EQ(std::count(other.err.begin(), other.err.end(), '\n'), 1) << other.err;
  EXPECT_TRUE(fs::exists(dir / "w" / "src" / "main.c"));
  EXPECT_FALSE(fs::exists(dir / "w" / "lock"));
  // A session holding a file of its owner's: refused, nothing removed.
  const testing::ProcessResult copy = testing::run_process("cp -r " + quoted(small_session().string()) + " " + quoted((dir / "S").string()));
  ASSERT_EQ(copy.exit_code, 0);
  testing::write_text(dir / "S" / "notes.txt", "mine\n");
  const testing::ProcessResult foreign = testing::run_bellows({"sessions", "rm", (dir / "S").string(), "--yes"});
  EXPECT_EQ(foreign.exit_code, 2) << foreign.err;
  EXPECT_NE(foreign.err.find("notes.txt"), std::string::npos) << foreign.err;
  EXPECT_TRUE(fs::exists(dir / "S" / "manifest.json"));
  fs::remove(dir / "S" / "notes.txt");
  // A link to a session: refused, the session stays.
  fs::create_directory_symlink(dir / "S", dir / "L");
  EXPECT_EQ(testing::run_bellows({"sessions", "rm", (dir / "L").string(), "--yes"}).exit_code, 2);
  EXPECT_TRUE(fs::exists(dir / "S" / "manifest.json"));
  // Answering no creates nothing (no lock file either).
  fs::remove(dir / "S" / "lock");
  const testing::ProcessResult no = testing::run_process("echo n | " + quoted(testing::kBellows) + " sessions rm " + quoted((dir / "S").string()));
  EXPECT_EQ(no.exit_code, 1) << no.err;
  EXPECT_FALSE(fs::exists(dir / "S" / "lock"));
  // A session: removed, every file of it, and the folder.
  const testing::ProcessResult yes = testing::run_bellows({"sessions", "rm", (dir / "S").string(), "--yes"});
  EXPECT_EQ(yes.exit_code, 0) << yes.err;
  EXPECT_FALSE(fs::exists(dir / "S"));
}

}  // namespace
}  // namespace bellows
