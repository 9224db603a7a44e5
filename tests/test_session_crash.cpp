// Crash safety: headless runs are killed with SIGKILL at random moments (some at random times,
// some the instant a file write has begun) and the session is loaded after each kill. It must
// always load and hold every iteration whose completion line had been printed; and a killed
// session must resume.
#include <signal.h>
#include <sys/inotify.h>
#include <sys/wait.h>

#include <chrono>
#include <cmath>
#include <random>
#include <cstdio>
#include <sstream>
#include <thread>

#include <gtest/gtest.h>

#include "engine/base/errors.hpp"
#include "session_test_support.hpp"
#include "sessions/atomic_file.hpp"
#include "sessions/session_layout.hpp"
#include "sessions/session_store.hpp"
#include "tests/test_support.hpp"

namespace bellows {
namespace {

using testing::TempDir;
namespace fs = std::filesystem;

using testing::read_until;

/// Blocks until the `count`-th temporary file is created in `directories` (a write has begun),
/// or until the timeout. Returns whether it happened.
bool wait_for_writes(const std::vector<fs::path>& directories, int count) {
  const int fd = ::inotify_init1(IN_CLOEXEC);
  if (fd < 0) return false;
  for (const fs::path& directory : directories) ::inotify_add_watch(fd, directory.c_str(), IN_CREATE);
  int seen = 0;
  alignas(inotify_event) char buffer[4096];
  while (seen < count) {
    pollfd poll_fd{fd, POLLIN, 0};
    if (::poll(&poll_fd, 1, 5000) <= 0) break;
    const ssize_t got = ::read(fd, buffer, sizeof buffer);
    for (ssize_t at = 0; at < got;) {
      const auto* event = reinterpret_cast<const inotify_event*>(buffer + at);
      if (event->len > 0 && is_temporary_file_name(event->name)) ++seen;
      at += static_cast<ssize_t>(sizeof(inotify_event) + event->len);
    }
  }
  ::close(fd);
  return seen >= count;
}

struct Printed {
  bool session_line = false;
  std::vector<std::pair<int, double>> iterations;  // number, RMS as printed
};

Printed parse_output(const std::string& out) {
  Printed printed;
  std::istringstream lines(out);
  std::string line;
  while (std::getline(lines, line)) {
    int iteration = 0;
    double rms = 0.0;
    // Only complete lines count: the last one may have been cut by the kill.
    if (std::sscanf(line.c_str(), "iteration %d rms %lf deg", &iteration, &rms) == 2 && !lines.eof()) {
      printed.iterations.emplace_back(iteration, rms);
    }
  }
  printed.session_line = out.rfind("session ", 0) == 0;
  return printed;
}

int temporary_files_in(const fs::path& directory) {
  int count = 0;
  std::error_code error;
  for (const fs::path& d : {directory, directory / session_layout::kIterations}) {
    for (const auto& entry : fs::directory_iterator(d, error)) count += is_temporary_file_name(entry.path().filename());
  }
  return count;
}

TEST(SessionCrash, EveryKilledRunLeavesASessionThatLoadsWithEveryPrintedIteration) {
  constexpr int kRounds = 24;
  // A kill at a write lands before the write ends in ~1 round in 4 (the writer keeps going between the
  // file's creation and the kill); on a loaded machine none of the 12 may. Rounds at a write then go on
  // until one has, so that the test always tests what it is for, up to this many more.
  constexpr int kMoreRoundsAtAWrite = 48;
  TempDir dir;
  testing::write_short_run_files(dir.path());
  const fs::path data = dir / "data";
  std::mt19937 random(20240501);
  int killed_mid_write = 0, loaded_sessions = 0, resumed_after_kill = 0;
  std::vector<std::string> loadable;  // sessions that survived, candidates to resume and kill again

  int round = 0;
  for (; round < kRounds || (killed_mid_write == 0 && round < kRounds + kMoreRoundsAtAWrite); ++round) {
    const bool resume = round % 3 == 2 && !loadable.empty();
    const std::string name = resume ? loadable.back() : "crash" + std::to_string(round);
    const fs::path session = data / name;
    const std::size_t before = resume ? load_session(session).iterations.size() : 0;
    std::vector<std::string> args;
    if (resume) {
      args = {"run", "--resume", session.string(), "--iterations", "100000"};
    } else {
      args = {"run",
              "--trajectory",
              (dir / "short.csv").string(),
              "--config",
              (dir / "short.toml").string(),
              "--iterations",
              "100000",
              "--data-dir",
              data.string(),
              "--name",
              name};
    }
    const testing::Spawned run = testing::spawn_bellows(args);
    std::string out;
    const bool at_a_write = round % 2 == 1 || round >= kRounds;
    if (at_a_write) {
      // Kill the instant the k-th file write of the run begins (manifest, samples or telemetry).
      out = read_until(run.out, "\n");  // "session DIR": the directories exist
      const int writes = std::uniform_int_distribution<int>(1, 10)(random);
      wait_for_writes({session, session / session_layout::kIterations}, writes);
    } else {
      // Anywhere: start-up, creating the directory, simulating, writing.
      std::this_thread::sleep_for(std::chrono::microseconds(std::uniform_int_distribution<int>(0, 120000)(random)));
    }
    ::kill(run.pid, SIGKILL);
    int status = 0;
    ::waitpid(run.pid, &status, 0);
    ASSERT_TRUE(WIFSIGNALED(status)) << "round " << round << ": the run ended before it was killed";
    out += read_until(run.out, "");
    ::close(run.out);
    ::close(run.err);
    const Printed printed = parse_output(out);

    std::error_code error;
    if (!fs::exists(session, error)) {
      // Killed before the session existed: then nothing can have been reported.
      EXPECT_FALSE(printed.session_line) << "round " << round << ": " << out;
      EXPECT_TRUE(printed.iterations.empty()) << "round " << round;
      continue;
    }
    const int leftovers = temporary_files_in(session);
    killed_mid_write += leftovers > 0;
    Session loaded;
    try {
      loaded = load_session(session);
    } catch (const InputError& load_error) {
      ADD_FAILURE() << "round " << round << " (" << (at_a_write ? "at a write" : "random")
                    << "): " << load_error.what();
      continue;
    }
    ++loaded_sessions;
    EXPECT_GE(loaded.iterations.size(), before) << "round " << round;
    for (const auto& [iteration, rms] : printed.iterations) {
      ASSERT_LT(static_cast<std::size_t>(iteration), loaded.iterations.size())
          << "round " << round << ": iteration " << iteration << " was printed but is not in the session";
      EXPECT_NEAR(loaded.manifest.iterations[static_cast<std::size_t>(iteration)].summary.rms_deg, rms, 0.0005)
          << "round " << round << ", iteration " << iteration;
    }
    if (!resume) loadable.push_back(name);
    if (round % 4 == 0) {
      // A killed session resumes: its lock died with its writer.
      const testing::ProcessResult resumed =
          testing::run_bellows({"run", "--resume", session.string(), "--iterations", "1"});
      EXPECT_EQ(resumed.exit_code, 0) << "round " << round << ": " << resumed.err;
      const std::size_t expected = loaded.iterations.size() + (loaded.iterations.empty() ? 2 : 1);
      EXPECT_EQ(load_session(session).iterations.size(), expected) << "round " << round;
      EXPECT_EQ(temporary_files_in(session), 0) << "a resume clears the leftovers of the killed write";
      ++resumed_after_kill;
    }
  }
  RecordProperty("loaded_sessions", loaded_sessions);
  RecordProperty("killed_mid_write", killed_mid_write);
  std::printf("crash test: %d kills, %d sessions loaded, %d kills left a write unfinished, %d resumed\n", round,
              loaded_sessions, killed_mid_write, resumed_after_kill);
  EXPECT_GE(killed_mid_write, 1) << "no kill landed during a write: the test did not test that";
  EXPECT_GE(loaded_sessions, kRounds / 2);
}

}  // namespace
}  // namespace bellows
