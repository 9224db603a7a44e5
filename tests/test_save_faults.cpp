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
#include <lcm/lcm-cpp.hpp>
#include <matio.h>
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

int count_of(const std::string& text, const std::string& what) {
  int n = 0;
  for (std::size_t at = text.find(what); at != std::string::npos; at = text.find(what, at + what.size())) ++n;
  return n;
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

/// `bellows run --resume SESSION --iterations 1` on the simulated clock: the resumed iteration's RMS.
double resumed_rms(const fs::path& session) {
  const testing::ProcessResult resumed =
      testing::run_bellows({"run", "--resume", session.string(), "--iterations", "1", "--clock", "sim", "--json"});
  EXPECT_EQ(resumed.exit_code, 0) << resumed.err;
  const nlohmann::json report = nlohmann::json::parse(resumed.out, nullptr, false);
  if (report.is_discarded() || !report.contains("iterations") || report["iterations"].size() != 1) {
    ADD_FAILURE() << "no resumed iteration: " << resumed.out << resumed.err;
    return -1.0;
  }
  return report["iterations"][0]["rms_deg"].get<double>();
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
  // The uninterrupted references, each resumed by the real binary: the session as the save under
  // test left it (the clean run), and as it was before that save (the driver quits instead).
  fs::create_directory(scratch / "before");
  const testing::ProcessResult before_run = testing::run_process(
      "BELLOWS_DRIVER_SKIP_ARMED_TRIAL=1 " + quoted(kDriver) + " " + quoted((scratch / "before").string()));
  ASSERT_EQ(before_run.exit_code, 0) << before_run.out << before_run.err;
  const Session before = load_session(session_in(scratch / "before"));
  ASSERT_EQ(before.iterations.size(), 2u);
  ASSERT_EQ(
      testing::run_process("cp -r " + quoted(clean.directory.string()) + " " + quoted((scratch / "after").string()))
          .exit_code,
      0);
  const double rms_after = resumed_rms(scratch / "after");
  const double rms_before = resumed_rms(session_in(scratch / "before"));
  int dropped_reported = 0, at_before = 0, at_learned = 0, at_after = 0;
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
    if (!loaded.dropped.empty()) {
      ++dropped_reported;
      EXPECT_NE(show.err.find("dropped"), std::string::npos) << show.err;
      EXPECT_NE(show.err.find(loaded.dropped), std::string::npos) << show.err;
    }
    // Every trial completed before that save, exactly as the clean run saved them.
    for (std::size_t i = 0; i < n; ++i) {
      EXPECT_EQ(loaded.iterations[i].record.joint_samples(0).angle_rad,
                clean.iterations[i].record.joint_samples(0).angle_rad)
          << i;
      EXPECT_EQ(loaded.iterations[i].record.joint_samples(0).u_ilc_bar,
                clean.iterations[i].record.joint_samples(0).u_ilc_bar)
          << i;
    }
    // Iteration 1's correction is the one learned from it (committed) or the one before (not yet):
    // never anything else; with iteration 2 listed, it is what iteration 2 ran with.
    const Eigen::MatrixXd next = loaded.iterations[n - 1].next_corrections_bar();
    const Eigen::MatrixXd next1 = loaded.iterations[1].next_corrections_bar();
    const Eigen::MatrixXd ran2 =
        clean.iterations[2].record.joint_samples(0).u_ilc_bar.head(clean.trajectory.learning_samples());
    const bool learned1 = next1.col(0) == ran2.col(0);
    if (n == 3) {
      EXPECT_TRUE(learned1) << "iteration 2 listed with another correction than it ran";
      EXPECT_TRUE(next == clean.iterations[2].next_corrections_bar())
          << "iteration 2's correction is not the clean run's";
    } else if (!learned1) {
      EXPECT_TRUE(next == before.iterations[1].next_corrections_bar())
          << "iteration 1's correction is neither learned nor the one before";
    }
    // `bellows run --resume` continues it: it takes the session as committed (what was dropped is
    // removed), runs iteration n with the committed correction on a freshly armed arm (the console
    // runs on the wall clock: its arm's state is not saved), and its RMS is, digit for digit, that
    // of the uninterrupted session with the same committed correction resumed: the clean run's
    // (iteration 1's learned correction is what iteration 2 ran with and kept), or the one before.
    const double rms = resumed_rms(session);
    if (next == clean.iterations[2].next_corrections_bar()) {
      ++(n == 3 ? at_after : at_learned);
      EXPECT_EQ(rms, rms_after) << "resumed with the clean run's correction: not the uninterrupted session's RMS";
    } else {
      ++at_before;
      EXPECT_EQ(rms, rms_before) << "resumed with the correction before the save: not the uninterrupted session's RMS";
    }
    const Session after = load_session(session);
    ASSERT_EQ(after.iterations.size(), n + 1);
    EXPECT_EQ(after.dropped, "");
    EXPECT_TRUE(after.iterations[n].record.joint_samples(0).u_ilc_bar.head(next.rows()) == next.col(0))
        << "the resumed iteration ran with another correction than the session committed";
  }
  // The sweep crossed both outcomes and the loader named what it dropped.
  EXPECT_GT(at_before + at_learned, 0);
  EXPECT_GT(at_after, 0);
  EXPECT_GT(dropped_reported, 0);
  std::printf(
      "console save: %d calls swept (kill, then sessions show and run --resume): %d left the state before the save "
      "(resumed RMS %.17g, as uninterrupted), %d iteration 1's learned correction without iteration 2 and %d the state "
      "after (resumed RMS %.17g, as uninterrupted); %d reported a drop\n",
      calls, at_before, rms_before, at_learned, at_after, rms_after, dropped_reported);
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
    const std::string failure =
        line_of(failed.out, "failure");  // the log line, also the status until a stop replaces it
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

/// A small session to write from (made once, by bellows itself, on a 0.5 s trajectory).
const fs::path& small_session() {
  static const fs::path made = [] {
    const fs::path data = testing::make_temp_dir("bellows-save-faults");
    testing::write_short_run_files(data);
    const testing::ProcessResult run =
        testing::run_bellows({"run", "--iterations", "2", "--trajectory", (data / "short.csv").string(), "--config",
                              (data / "short.toml").string(), "--data-dir", data.string(), "--name", "s"});
    EXPECT_EQ(run.exit_code, 0) << run.err;
    return data / "s";
  }();
  return made;
}

/// The shortest identification the fit accepts ([identify] duration_s at its 3 s floor, no settle).
const fs::path& short_identification_config() {
  static const fs::path made = [] {
    const fs::path dir = testing::make_temp_dir("bellows-save-faults-identify");
    testing::write_text(dir / "identify.toml", "[identify]\nduration_s = 3\n[timing]\nsettle_s = 0\n");
    return dir / "identify.toml";
  }();
  return made;
}

struct Writer {
  std::string name;
  /// The shell command writing into `out` (a fresh folder); the files it writes there (in
  /// `folder`, relative to `out`).
  std::function<std::string(const fs::path& out)> command;
  std::vector<std::string> outputs = {};
  std::string folder = "";
  /// Whether `file` is a whole copy of the clean run's `clean_file` (default: the same bytes).
  std::function<bool(const fs::path& file, const fs::path& clean_file)> whole = {};
  /// An output that exists before the command runs (it replaces it with --force): its old text,
  /// which a kill or a failure may leave instead of the new one.
  std::string previous_text = "";
  /// Sweep every `stride`-th call (and always the last 4: flush, rename, flush of the folder),
  /// for a library that writes in hundreds of small pieces (HDF5).
  int stride = 1;
};

bool same_bytes(const fs::path& file, const fs::path& clean_file) {
  return testing::read_text(file) == testing::read_text(clean_file);
}

/// A MAT file libmatio reads whole: as many bytes as the clean one (the header's date differs) and
/// its three variables there.
bool whole_mat_file(const fs::path& file, const fs::path& clean_file) {
  if (fs::file_size(file) != fs::file_size(clean_file)) return false;
  mat_t* mat = Mat_Open(file.c_str(), MAT_ACC_RDONLY);
  if (mat == nullptr) return false;
  std::set<std::string> names;
  while (matvar_t* var = Mat_VarReadNext(mat)) {
    if (var->name != nullptr) names.insert(var->name);
    Mat_VarFree(var);
  }
  Mat_Close(mat);
  return names == std::set<std::string>{"session", "iterations", "black_boxes"};
}

/// An LCM event log with every event of the clean one (the session id and times differ): the same
/// size, and LCM's reader finds the same channels in the same order to the end.
bool whole_lcm_log(const fs::path& file, const fs::path& clean_file) {
  if (fs::file_size(file) != fs::file_size(clean_file)) return false;
  const auto channels = [](const fs::path& path) {
    std::vector<std::string> out;
    lcm::LogFile log(path.string(), "r");
    if (!log.good()) return out;
    for (const lcm::LogEvent* e = log.readNextEvent(); e != nullptr; e = log.readNextEvent()) out.push_back(e->channel);
    return out;
  };
  const std::vector<std::string> got = channels(file);
  return !got.empty() && got == channels(clean_file);
}

/// Each output in `out` is absent or whole (the clean run's, or the one it replaces); nothing else
/// is there but hidden temporaries (a kill) or nothing at all (a failure, which cleans up).
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
    const bool previous = !writer.previous_text.empty() && testing::read_text(p) == writer.previous_text;
    EXPECT_TRUE(previous || (writer.whole ? writer.whole : same_bytes)(p, clean / name)) << name << " is partial";
  }
}

/// Counts the calls of a clean run, then kills the writer before call k, and fails call k with
/// ENOSPC, for every k: each output absent or whole, never a link, nothing else written; killed,
/// status 137; failed, one line naming the full disk, exit status 4 (the environment refused) and
/// no temporary left.
void sweep_writer(const Writer& writer) {
  SCOPED_TRACE(writer.name);
  TempDir scratch;
  fs::create_directory(scratch / "clean");
  const int calls = counted_calls(writer.command(scratch / "clean"), scratch.path());
  ASSERT_GE(calls, 3) << "write, fsync, rename at least";
  int swept = 0, harmless = 0;
  for (const std::string mode : {"kill", "enospc"}) {
    for (int k = 1; k <= calls; ++k) {
      if (k % writer.stride != 1 % writer.stride && k <= calls - 4) continue;
      SCOPED_TRACE(mode + " at call " + std::to_string(k) + " of " + std::to_string(calls));
      const fs::path out = scratch / (mode + std::to_string(k));
      fs::create_directory(out);
      const std::string command = writer.command(out);
      const testing::ProcessResult result = run_faulted(command, mode, k);
      ++swept;
      if (mode == std::string("kill")) {
        EXPECT_EQ(result.exit_code, 128 + SIGKILL) << result.err;
      } else if (result.exit_code == 0) {
        // Only a call whose failure loses nothing (the lock file's note of its holder): every output
        // there and whole.
        ++harmless;
        if (writer.name.rfind("sessions rename", 0) != 0) {
          for (const std::string& name : writer.outputs)
            EXPECT_TRUE(fs::exists(out / writer.folder / name)) << "reported done without " << name;
        }
      } else {
        const std::string said = result.out + result.err;  // run says it beside its progress, on stdout
        EXPECT_EQ(count_of(said, "No space left on device"), 1) << "said once: " << said;
        EXPECT_EQ(result.exit_code, kExitEnvironment) << "a disk that cannot be written: " << said;
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
      if (!writer.folder.empty()) {  // nothing beside the writer's folder
        for (const fs::path& p : entries(out))
          EXPECT_EQ(p.filename().string(), writer.folder) << "written outside: " << p;
      }
      expect_whole_outputs(out / writer.folder, scratch / "clean" / writer.folder, writer, mode == std::string("kill"));
    }
  }
  std::printf(
      "%s: %d calls, %d runs swept (kill and ENOSPC at %s; %d ENOSPC lost nothing and exited 0)\n", writer.name.c_str(),
      calls, swept,
      writer.stride == 1 ? "every call" : ("every " + std::to_string(writer.stride) + "th call and the last 4").c_str(),
      harmless);
}

std::string bellows_command(const std::string& arguments) { return quoted(testing::kBellows) + " " + arguments; }

/// `bellows run` saving its session on a disk that fills: failed at each call k, one line naming
/// the full disk and exit status 4 (the environment refused: not 2, which says nothing was changed,
/// while the trials before it are saved), and what is on disk is a session that loads with the
/// iterations committed before the failure.
TEST_F(SaveFaults, RunOnAFullDiskSaysSoOnceExitsFourAndKeepsWhatItCommitted) {
  const fs::path files = small_session().parent_path();  // short.csv, short.toml
  TempDir scratch;
  const auto command = [&](const fs::path& data) {
    return bellows_command("run --iterations 2 --trajectory " + quoted((files / "short.csv").string()) + " --config " +
                           quoted((files / "short.toml").string()) + " --data-dir " + quoted(data.string()) +
                           " --name s");
  };
  fs::create_directory(scratch / "clean");
  const int calls = counted_calls(command(scratch / "clean"), scratch.path());
  ASSERT_GE(calls, 9) << "three iterations, each written, flushed and renamed at least";
  int failed = 0;
  for (int k = 1; k <= calls; ++k) {
    SCOPED_TRACE("ENOSPC at call " + std::to_string(k) + " of " + std::to_string(calls));
    const fs::path data = scratch / ("k" + std::to_string(k));
    fs::create_directory(data);
    const testing::ProcessResult result = run_faulted(command(data), "enospc", k);
    if (result.exit_code == 0) continue;  // a call whose failure loses nothing (the lock file's note)
    ++failed;
    const std::string said = result.out + result.err;
    EXPECT_EQ(result.exit_code, kExitEnvironment) << said;
    EXPECT_EQ(count_of(said, "No space left on device"), 1) << "said once: " << said;
    if (!fs::exists(data / "s")) continue;  // failed before the session was first committed
    const testing::ProcessResult show = testing::run_bellows({"sessions", "show", (data / "s").string()});
    EXPECT_EQ(show.exit_code, 0) << show.err;
    for (const fs::path& p : entries(data / "s")) EXPECT_FALSE(is_temporary_file_name(p.filename().string())) << p;
  }
  EXPECT_GT(failed, calls / 2) << "most calls of a save lose something when they fail";
  std::printf("run: %d calls swept (ENOSPC), %d failed with exit status 4\n", calls, failed);
}

TEST_F(SaveFaults, EveryWriterKilledOrFailedAtEveryCallLeavesWholeFilesOrNone) {
  const fs::path session = small_session();
  ASSERT_TRUE(fs::is_directory(session));
  sweep_writer({.name = "sessions export",
                .command =
                    [&](const fs::path& out) {
                      return bellows_command("sessions export " + quoted(session.string()) + " --output " +
                                             quoted((out / "e.csv").string()));
                    },
                .outputs = {"e.csv", "e_telemetry.csv", "e_summary.csv"}});
  sweep_writer({.name = "trajectories --output",
                .command =
                    [](const fs::path& out) {
                      return bellows_command("trajectories paper --output " + quoted((out / "t.csv").string()));
                    },
                .outputs = {"t.csv"}});
  sweep_writer({.name = "sessions rename (the manifest)",
                .command =
                    [&](const fs::path& out) {
                      const testing::ProcessResult copy = testing::run_process("cp -r " + quoted(session.string()) +
                                                                               " " + quoted((out / "a").string()));
                      EXPECT_EQ(copy.exit_code, 0);
                      return bellows_command("sessions rename " + quoted((out / "a").string()) + " b");
                    },
                .outputs = {"a", "b"}});
}

TEST_F(SaveFaults, TheMatExportKilledOrFailedAtEveryCallLeavesAWholeFileOrNone) {
  const fs::path session = small_session();
  // MAT v5: libmatio writes into memory, the safe writer writes it out.
  sweep_writer({.name = "sessions export --format mat",
                .command =
                    [&](const fs::path& out) {
                      return bellows_command("sessions export " + quoted(session.string()) + " --format mat --output " +
                                             quoted((out / "e.mat").string()));
                    },
                .outputs = {"e.mat"},
                .whole = whole_mat_file});
  // MAT v7.3: HDF5 writes in its private folder (hundreds of pwrites), then fsync, rename, fsync.
  sweep_writer({.name = "sessions export --format mat --mat-version 7.3",
                .command =
                    [&](const fs::path& out) {
                      return bellows_command("sessions export " + quoted(session.string()) +
                                             " --format mat --mat-version 7.3 --output " +
                                             quoted((out / "e.mat").string()));
                    },
                .outputs = {"e.mat"},
                .whole = whole_mat_file,
                .stride = 150});
}

TEST_F(SaveFaults, TheLcmLogKilledOrFailedAtEveryCallIsWholeOrAbsent) {
  const fs::path session = small_session();
  const fs::path files = session.parent_path();  // short.csv, short.toml
  sweep_writer({.name = "run --lcm-log",
                .command =
                    [&](const fs::path& out) {
                      return bellows_command("run --iterations 0 --no-save --seed 3 --trajectory " +
                                             quoted((files / "short.csv").string()) + " --config " +
                                             quoted((files / "short.toml").string()) + " --lcm-log " +
                                             quoted((out / "t.lcmlog").string()));
                    },
                .outputs = {"t.lcmlog"},
                .whole = whole_lcm_log});
}

TEST_F(SaveFaults, PlotAndIdentifyKilledOrFailedAtEveryCallLeaveWholeFilesOrNone) {
  const fs::path session = small_session();
  // sessions plot: the script, then each figure gnuplot drew in its private folder, published.
  sweep_writer({.name = "sessions plot",
                .command =
                    [&](const fs::path& out) {
                      return bellows_command("sessions plot " + quoted(session.string()) +
                                             " --formats svg --no-paper --output " + quoted((out / "fig").string()));
                    },
                .outputs = {"figures.gp", "rms.svg", "angle.svg", "error.svg", "u_ilc.svg", "pressures.svg"},
                .folder = "fig"});
  // identify --write-model: a new configuration, and one whose model --force replaces.
  const std::string identify =
      "identify --no-save --config " + quoted(short_identification_config().string()) + " --write-model ";
  sweep_writer(
      {.name = "identify --write-model (new file)",
       .command = [&](const fs::path& out) { return bellows_command(identify + quoted((out / "m.toml").string())); },
       .outputs = {"m.toml"}});
  const std::string previous = "# the lab's configuration\n[model]\nkappa = 7.0\nomega0 = 14.0\ndamping = 0.3\n";
  sweep_writer({.name = "identify --write-model --force (replacing a model)",
                .command =
                    [&](const fs::path& out) {
                      testing::write_text(out / "m.toml", previous);
                      return bellows_command(identify + quoted((out / "m.toml").string()) + " --force");
                    },
                .outputs = {"m.toml"},
                .previous_text = previous});
}

// --- symbolic links planted where a writer writes -----------------------------------------------

TEST_F(SaveFaults, LinksPlantedAtTheOldTemporaryNamesWriteNothingOutside) {
  const fs::path session = small_session();
  TempDir dir;
  const fs::path victim = dir / "victim";
  testing::write_text(victim, "precious\n");
  const testing::ProcessResult copy =
      testing::run_process("cp -r " + quoted(session.string()) + " " + quoted((dir / "S").string()));
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
    const testing::ProcessResult result =
        testing::run_process("bash -c " + quoted("ln -sf " + victim.string() + " " + out.string() + "/" + planted +
                                                 "; exec " + testing::kBellows + " " + command));
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
  const testing::ProcessResult forced =
      testing::run_bellows({"trajectories", "steps", "--output", existing.string(), "--force"});
  EXPECT_EQ(forced.exit_code, 0) << forced.err;
  EXPECT_NE(testing::read_text(existing), "mine\n");
  // A link at the output: refused without --force; with it, the link is replaced, never followed.
  fs::create_symlink(victim, dir / "link.csv");
  EXPECT_EQ(testing::run_bellows({"trajectories", "steps", "--output", (dir / "link.csv").string()}).exit_code, 2);
  EXPECT_EQ(
      testing::run_bellows({"trajectories", "steps", "--output", (dir / "link.csv").string(), "--force"}).exit_code, 0);
  EXPECT_FALSE(fs::is_symlink(dir / "link.csv"));
  EXPECT_EQ(testing::read_text(victim), "precious\n");
  // The LCM log: a dangling link at its name is refused, and nothing is created through it.
  fs::create_symlink(dir / "created-through-link", dir / "log.lcmlog");
  const testing::ProcessResult log =
      testing::run_bellows({"run", "--iterations", "1", "--no-save", "--lcm-log", (dir / "log.lcmlog").string()});
  EXPECT_EQ(log.exit_code, 2) << log.err;
  EXPECT_FALSE(fs::exists(dir / "created-through-link"));
}

// --- identify --write-model: never replaces a model in silence ------------------------------------

TEST_F(SaveFaults, IdentifyWriteModelAddsAModelButReplacesOneOnlyWithForce) {
  TempDir dir;
  const std::vector<std::string> identify = {"identify", "--no-save", "--config",
                                             short_identification_config().string(), "--write-model"};
  const auto with = [&](std::vector<std::string> extra) {
    std::vector<std::string> args = identify;
    args.insert(args.end(), extra.begin(), extra.end());
    return testing::run_bellows(args);
  };
  // A file that does not exist: created.
  const fs::path fresh = dir / "fresh.toml";
  ASSERT_EQ(with({fresh.string()}).exit_code, 0);
  const std::string fitted = testing::read_text(fresh);
  EXPECT_NE(fitted.find("kappa = "), std::string::npos) << fitted;
  // It holds a model now: refused before any trial, in one line naming it, the file untouched.
  const testing::ProcessResult again = with({fresh.string()});
  EXPECT_EQ(again.exit_code, 2) << again.err;
  EXPECT_NE(again.err.find("holds a model already ([model] kappa = "), std::string::npos) << again.err;
  EXPECT_NE(again.err.find("--force replaces it"), std::string::npos) << again.err;
  EXPECT_EQ(std::count(again.err.begin(), again.err.end(), '\n'), 1) << again.err;
  EXPECT_EQ(again.out.find("identification trial"), std::string::npos)
      << "a trial ran before the refusal: " << again.out;
  EXPECT_EQ(testing::read_text(fresh), fitted);
  // A configuration without a model: the model is added, the rest kept, no --force needed.
  const fs::path lab = dir / "lab.toml";
  testing::write_text(lab, "# the lab's settings\n[timing]\nsettle_s = 0\n");
  ASSERT_EQ(with({lab.string()}).exit_code, 0);
  EXPECT_EQ(testing::read_text(lab).rfind("# the lab's settings\n[timing]\nsettle_s = 0\n", 0), 0u)
      << testing::read_text(lab);
  EXPECT_NE(testing::read_text(lab).find("[model]"), std::string::npos);
  // A rig profile with a model: refused; with --force, replaced (its other tables kept).
  const fs::path profile = dir / "rig.toml";
  testing::write_text(profile, testing::read_text(fs::path(BELLOWS_SOURCE_DIR) / "profiles" / "paper-rig.toml") +
                                   "\n[model]\nkappa_rad_per_bar = 7.0\nomega0_rad_per_s = 14.0\ndamping = 0.3\n");
  const testing::ProcessResult refused = with({profile.string()});
  EXPECT_EQ(refused.exit_code, 2) << refused.err;
  EXPECT_NE(refused.err.find("[model] kappa_rad_per_bar = 7"), std::string::npos) << refused.err;
  const testing::ProcessResult forced = with({profile.string(), "--force"});
  EXPECT_EQ(forced.exit_code, 0) << forced.err;
  EXPECT_EQ(testing::read_text(profile).find("kappa_rad_per_bar = 7.0\n"), std::string::npos) << "not replaced";
  EXPECT_NE(testing::read_text(profile).find("[valves]"), std::string::npos);
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
  const testing::ProcessResult copy =
      testing::run_process("cp -r " + quoted(small_session().string()) + " " + quoted((dir / "S").string()));
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
  const testing::ProcessResult no =
      testing::run_process("echo n | " + quoted(testing::kBellows) + " sessions rm " + quoted((dir / "S").string()));
  EXPECT_EQ(no.exit_code, 1) << no.err;
  EXPECT_FALSE(fs::exists(dir / "S" / "lock"));
  // A session: removed, every file of it, and the folder.
  const testing::ProcessResult yes = testing::run_bellows({"sessions", "rm", (dir / "S").string(), "--yes"});
  EXPECT_EQ(yes.exit_code, 0) << yes.err;
  EXPECT_FALSE(fs::exists(dir / "S"));
}

}  // namespace
}  // namespace bellows
