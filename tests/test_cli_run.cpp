// End-to-end tests of `bellows run`: the paper's learning curve, model mismatch, bad input.
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include "engine/base/errors.hpp"
#include "tests/process_runner.hpp"

namespace bellows {
namespace {

using testing::run_process;
using testing::write_file;

nlohmann::json run_json(const std::string& args) {
  const auto result = run_process(std::string(BELLOWS_BINARY) + " run --json --no-save " + args);
  EXPECT_EQ(result.exit_code, 0) << result.err;
  return nlohmann::json::parse(result.out);
}

using testing::rms_sequence;

TEST(CliRun, ReproducesThePapersLearningCurve) {
  const nlohmann::json report = run_json("--trajectory paper --iterations 60");
  const std::vector<double> rms = rms_sequence(report);
  ASSERT_EQ(rms.size(), 61u);
  for (int i = 0; i <= 60; ++i) EXPECT_EQ(report["iterations"][i]["iteration"].get<int>(), i);
  EXPECT_GE(rms[0], 10.0);
  EXPECT_LE(rms[0], 16.0);
  EXPECT_LT(rms[30], 2.0);
  EXPECT_GE((rms[0] - rms[10]) / (rms[0] - rms[30]), 0.85);
  for (int i = 30; i <= 60; ++i) EXPECT_LE(rms[i], 2.5) << "iteration " << i;
  for (const auto& it : report["iterations"]) {
    EXPECT_GE(it.at("max_abs_error_deg").get<double>(), it.at("rms_deg").get<double>());
    EXPECT_GE(it.at("max_abs_correction_bar").get<double>(), 0.0);
  }
  EXPECT_EQ(report["iterations"][0]["max_abs_correction_bar"].get<double>(), 0.0);  // feedback only
  EXPECT_GT(report["iterations"][30]["max_abs_correction_bar"].get<double>(), 0.1);
}

TEST(CliRun, ConvergesWithAModelTwentyPercentOff) {
  const auto dir = testing::make_temp_dir("bellows-mismatch");
  for (double factor : {1.2, 0.8}) {
    const auto config = write_file(
        dir, "mismatch.toml",
        "[plant]\nkappa = " + std::to_string(7.91 * factor) + "\nomega0 = " + std::to_string(14.14 * factor) + "\n");
    const std::vector<double> rms = rms_sequence(run_json("--iterations 30 --config " + config.string()));
    ASSERT_EQ(rms.size(), 31u);
    EXPECT_LE(rms[30], rms[0] / 3.0) << "plant factor " << factor;
  }
}

TEST(CliRun, SameSeedSameRunOtherSeedOtherNoise) {
  const auto a = rms_sequence(run_json("--iterations 2 --seed 11"));
  const auto b = rms_sequence(run_json("--iterations 2 --seed 11"));
  const auto c = rms_sequence(run_json("--iterations 2 --seed 12"));
  EXPECT_EQ(a, b);
  EXPECT_NE(a, c);
}

TEST(CliRun, RunsACsvTrajectory) {
  const auto dir = testing::make_temp_dir("bellows-csv");
  std::string text = "time_s,angle_deg\n";
  for (int k = 0; k <= 150; ++k) text += std::to_string(k * 0.02) + "," + std::to_string(k < 50 ? 0.0 : 20.0) + "\n";
  const auto path = write_file(dir, "step.csv", text);
  const nlohmann::json report = run_json("--iterations 3 --trajectory " + path.string());
  EXPECT_EQ(report["trajectory"], "step");
  EXPECT_EQ(report["samples"], 150);
  EXPECT_LT(report["iterations"][3]["rms_deg"].get<double>(), report["iterations"][0]["rms_deg"].get<double>());
}

// A short step trajectory and a short settle: a wall-clock run that takes about a second.
std::string short_wall_run_args(const std::string& tag) {
  const auto dir = testing::make_temp_dir(tag);
  std::string text = "time_s,angle_deg\n";
  for (int k = 0; k <= 40; ++k) text += std::to_string(k * 0.02) + "," + std::to_string(k < 10 ? 0.0 : 10.0) + "\n";
  const auto trajectory = write_file(dir, "step.csv", text);
  const auto config = write_file(dir, "short.toml", "[timing]\nsettle_s = 0.2\n");
  return "--iterations 1 --trajectory " + trajectory.string() + " --config " + config.string();
}

TEST(CliRun, WallClockRunReportsItsLoop) {
  const nlohmann::json report = run_json("--clock wall --speed 2 " + short_wall_run_args("bellows-wall-loop"));
  ASSERT_TRUE(report.contains("loop")) << report.dump();
  const nlohmann::json& loop = report["loop"];
  // Two trials of 0.8 s plus settles at 200 Hz: hundreds of ticks, each with a wake-up latency.
  EXPECT_GT(loop["ticks"].get<int>(), 2 * 160);
  EXPECT_GE(loop["missed"].get<int>(), 0);
  const nlohmann::json& latency = loop["latency_us"];
  EXPECT_GE(latency["p50"].get<double>(), 0.0);
  EXPECT_LE(latency["p50"].get<double>(), latency["p99"].get<double>());
  EXPECT_LE(latency["p99"].get<double>(), latency["max"].get<double>() + 1.0);  // bins are 1 us wide
  const std::string rt = loop["rt"].get<std::string>();
  EXPECT_TRUE(rt == "fifo" || rt == "other") << rt;
  EXPECT_TRUE(loop["cpu_wakeup_limit_us"].is_null() || loop["cpu_wakeup_limit_us"].get<int>() == 0);
}

TEST(CliRun, RealtimeOffAsksForNothing) {
  const nlohmann::json report = run_json("--clock wall --speed 2 --rt off " + short_wall_run_args("bellows-wall-off"));
  EXPECT_EQ(report["loop"]["rt"], "other");
  EXPECT_TRUE(report["loop"]["cpu_wakeup_limit_us"].is_null());
}

TEST(CliRun, SimulatedClockRunHasNoLoopReport) {
  const nlohmann::json report = run_json(short_wall_run_args("bellows-sim-loop"));
  EXPECT_FALSE(report.contains("loop"));
}

void expect_bad_input(const std::string& args, const std::string& fragment) {
  const auto result = run_process(std::string(BELLOWS_BINARY) + " run --json --no-save " + args);
  EXPECT_EQ(result.exit_code, 2) << args;
  EXPECT_TRUE(result.out.empty()) << "partial result printed for " << args << ": " << result.out;
  EXPECT_NE(result.err.find(fragment), std::string::npos) << result.err;
  // One clear line: a single newline at the end.
  EXPECT_EQ(std::count(result.err.begin(), result.err.end(), '\n'), 1) << result.err;
}

TEST(CliRun, BadInputGetsOneLineAndExitStatusTwo) {
  const auto dir = testing::make_temp_dir("bellows-bad");
  const std::string good_rows = "0,0\n0.02,1\n0.04,2\n";
  expect_bad_input("--trajectory " + write_file(dir, "header.csv", "t,deg\n" + good_rows).string(), "header");
  expect_bad_input("--trajectory " + write_file(dir, "gap.csv", "time_s,angle_deg\n0,0\n0.02,1\n0.05,2\n").string(),
                   "not uniform");
  expect_bad_input("--trajectory " + write_file(dir, "nan.csv", "time_s,angle_deg\n0,0\n0.02,nan\n0.04,2\n").string(),
                   "not a number");
  expect_bad_input("--trajectory " + write_file(dir, "far.csv", "time_s,angle_deg\n0,0\n0.02,100\n0.04,2\n").string(),
                   "joint range");
  expect_bad_input("--trajectory " + (dir / "missing.csv").string(), "cannot be read");
  expect_bad_input("--trajectory loops", "unknown trajectory");
  expect_bad_input("--config " + write_file(dir, "key.toml", "[plant]\nkapa = 1.0\n").string(), "unknown key");
  expect_bad_input("--config " + write_file(dir, "type.toml", "[ilc]\ns = \"big\"\n").string(), "expected a number");
  expect_bad_input("--config " + write_file(dir, "tau.toml", "[plant]\ncreep_tau_s = 0\n").string(), "must be in (0, ");
  expect_bad_input("--config " + write_file(dir, "taup.toml", "[controller]\ntau_p_s = -1\n").string(),
                   "must be in (0, ");
  expect_bad_input("--config " + (dir / "none.toml").string(), "cannot be read");
  expect_bad_input("--iterations -3", "iterations");
  expect_bad_input("--iterations many", "iterations");
}

// Runs `bellows ARGS` on a pseudo-terminal (util-linux `script`), as an operator's shell would.
testing::ProcessResult run_on_terminal(const std::string& args) {
  return run_process("script -qec '" + std::string(BELLOWS_BINARY) + " " + args + "' /dev/null");
}

std::size_t count(const std::string& text, const std::string& part) {
  std::size_t n = 0;
  for (std::size_t at = text.find(part); at != std::string::npos; at = text.find(part, at + part.size())) ++n;
  return n;
}

TEST(CliRun, ProgressIsOneRedrawnLineOnATerminalAndALinePerIterationElsewhere) {
  // Into a pipe: a line per iteration 0..3, nothing a terminal would interpret.
  const auto piped = run_process(std::string(BELLOWS_BINARY) + " run --no-save --iterations 3");
  ASSERT_EQ(piped.exit_code, 0) << piped.err;
  for (int i = 0; i <= 3; ++i)
    EXPECT_EQ(count(piped.out, "iteration   " + std::to_string(i) + "  rms"), 1u) << piped.out;
  EXPECT_EQ(count(piped.out, "\n"), 4u) << piped.out;
  EXPECT_EQ(piped.out.find_first_of("\r\x1b"), std::string::npos) << piped.out;

  // On a terminal: one line, redrawn for each iteration (carriage return, erase to the end), that
  // names the iteration, its RMS and the time left, and ends with one newline when the run is done.
  const auto shown = run_on_terminal("run --no-save --iterations 3");
  ASSERT_EQ(shown.exit_code, 0) << shown.out << shown.err;
  for (int i = 0; i <= 3; ++i)
    EXPECT_EQ(count(shown.out, "\riteration " + std::to_string(i) + " of 0..3  rms "), 1u) << shown.out;
  EXPECT_EQ(count(shown.out, "ETA "), 3u) << shown.out;
  EXPECT_EQ(count(shown.out, "done in "), 1u) << shown.out;
  EXPECT_EQ(count(shown.out, "\x1b[K"), 4u) << shown.out;
  EXPECT_EQ(count(shown.out, "\n"), 1u) << shown.out;  // the terminal turns it into \r\n
  EXPECT_EQ(shown.out.find("max error"), std::string::npos) << shown.out;

  // --verbose on a terminal: the lines again.
  const auto verbose = run_on_terminal("run --no-save --iterations 3 --verbose");
  ASSERT_EQ(verbose.exit_code, 0) << verbose.out;
  EXPECT_EQ(count(verbose.out, "max error"), 4u) << verbose.out;
  EXPECT_EQ(verbose.out.find("\x1b[K"), std::string::npos) << verbose.out;
}

TEST(CliRun, QuietPrintsNothingButErrorsAndTheJson) {
  const auto shown = run_on_terminal("run --iterations 2 --quiet --name quiet");  // saved: not even its directory
  ASSERT_EQ(shown.exit_code, 0) << shown.out;
  EXPECT_EQ(shown.out, "");
  const auto piped = run_process(std::string(BELLOWS_BINARY) + " run --no-save --iterations 2 --quiet --json");
  ASSERT_EQ(piped.exit_code, 0) << piped.err;
  EXPECT_EQ(piped.err, "");
  EXPECT_EQ(nlohmann::json::parse(piped.out)["iterations"].size(), 3u);  // iterations 0..2
  // Errors still say what went wrong.
  const auto wrong = run_process(std::string(BELLOWS_BINARY) + " run --no-save --quiet --trajectory loops");
  EXPECT_EQ(wrong.exit_code, 2);
  EXPECT_NE(wrong.err.find("unknown trajectory"), std::string::npos) << wrong.err;
  EXPECT_EQ(run_process(std::string(BELLOWS_BINARY) + " run --no-save --quiet --verbose").exit_code, 2);
}

}  // namespace
}  // namespace bellows

#include <signal.h>
#include <fcntl.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <fstream>
#include <iterator>
#include <thread>

extern char** environ;

namespace bellows {
namespace {

// Starts `bellows args...` with stdout into a pipe; returns pid and the pipe's read end. In a process
// group of its own when asked: a group whose parent is in another group of the session is not
// orphaned, so that a stop signal (SIGTSTP) is not discarded by the kernel but acted on.
std::pair<pid_t, int> spawn_bellows(std::vector<std::string> args, bool own_process_group = false) {
  int pipe_fds[2];
  EXPECT_EQ(pipe(pipe_fds), 0);
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_adddup2(&actions, pipe_fds[1], STDOUT_FILENO);
  posix_spawn_file_actions_addclose(&actions, pipe_fds[0]);
  posix_spawn_file_actions_addopen(&actions, STDERR_FILENO, "/dev/null", O_WRONLY, 0);
  args.insert(args.begin(), BELLOWS_BINARY);
  std::vector<char*> argv;
  for (auto& a : args) argv.push_back(a.data());
  argv.push_back(nullptr);
  posix_spawnattr_t attributes;
  posix_spawnattr_init(&attributes);
  if (own_process_group) {
    posix_spawnattr_setflags(&attributes, POSIX_SPAWN_SETPGROUP);
    posix_spawnattr_setpgroup(&attributes, 0);
  }
  pid_t pid = -1;
  EXPECT_EQ(posix_spawn(&pid, BELLOWS_BINARY, &actions, &attributes, argv.data(), environ), 0);
  posix_spawnattr_destroy(&attributes);
  posix_spawn_file_actions_destroy(&actions);
  close(pipe_fds[1]);
  return {pid, pipe_fds[0]};
}

std::string read_all(int fd) {
  std::string text;
  char buffer[4096];
  ssize_t n;
  while ((n = read(fd, buffer, sizeof buffer)) > 0) text.append(buffer, static_cast<std::size_t>(n));
  close(fd);
  return text;
}

TEST(CliRun, SigintVentsAndExitsCleanlyWithWhatFinished) {
  // SIGHUP (the terminal closed, an ssh session dropped) is handled like SIGINT and SIGTERM.
  for (int signal_number : {SIGINT, SIGTERM, SIGHUP}) {
    setenv("XDG_DATA_HOME", testing::make_temp_dir("bellows-xdg").c_str(), 1);  // never the real home
    auto [pid, out] = spawn_bellows({"run", "--clock", "wall", "--speed", "5", "--iterations", "50", "--json"});
    std::this_thread::sleep_for(std::chrono::milliseconds(2500));  // past the first trial (~1.8 s)
    kill(pid, signal_number);
    const std::string text = read_all(out);
    int status = 0;
    waitpid(pid, &status, 0);
    ASSERT_TRUE(WIFEXITED(status)) << "killed by a signal instead of exiting cleanly";
    EXPECT_EQ(WEXITSTATUS(status), 128 + signal_number);
    const nlohmann::json report = nlohmann::json::parse(text);
    EXPECT_EQ(report["fault"]["name"], "emergency-stop");
    const std::string name = signal_number == SIGINT ? "SIGINT" : signal_number == SIGTERM ? "SIGTERM" : "SIGHUP";
    EXPECT_EQ(report["fault"]["message"], "interrupted by " + name + ": valves vented");
    EXPECT_EQ(report["dropped_events"], 0);
    EXPECT_GE(report["iterations"].size(), 1u);
    EXPECT_LT(report["iterations"].size(), 51u);
  }
}

/// `bellows run | head -n 1` (or a `tee` that ended): the run's next line meets a pipe with no
/// reader. SIGPIPE's default would end bellows there and then, the valves as they were and the fault
/// not saved; it stops the run as SIGINT does: vented, the finished iterations and the fault event in
/// the session, exit status 4 with one line on stderr (standard output could not be written).
TEST(CliRun, AReaderOfTheOutputThatGoesAwayStopsTheRunVentedAndSaved) {
  const std::filesystem::path data = testing::make_temp_dir("bellows-broken-pipe");
  const std::string quoted_data = "'" + data.string() + "'";
  // A script of its own: run_process() puts an assignment before the command, which a { ...; } group refuses.
  write_file(data, "pipe.sh",
             "{ '" + testing::kBellows + "' run --clock wall --speed 5 --iterations 50 --data-dir " + quoted_data +
                 " --name s 2> " + quoted_data + "/err.txt; echo $? > " + quoted_data + "/status.txt; } | head -n 1\n");
  const testing::ProcessResult piped = run_process("sh " + quoted_data + "/pipe.sh");
  EXPECT_NE(piped.out.find("session "), std::string::npos) << piped.out;
  std::ifstream status_file(data / "status.txt");
  int status = -1;
  status_file >> status;
  EXPECT_EQ(status, kExitEnvironment) << "141: ended by SIGPIPE, the valves as they were";
  std::ifstream err_file(data / "err.txt");
  const std::string err((std::istreambuf_iterator<char>(err_file)), std::istreambuf_iterator<char>());
  EXPECT_EQ(err, "bellows: cannot write to standard output: Broken pipe\n");
  const testing::ProcessResult show = run_process(testing::kBellows + " sessions show " + quoted_data + "/s");
  ASSERT_EQ(show.exit_code, 0) << show.err;
  EXPECT_NE(show.out.find("fault: interrupted by SIGPIPE: valves vented (emergency-stop)"), std::string::npos)
      << show.out;
  EXPECT_NE(show.out.find("iterations   0"), std::string::npos) << "iteration 0 saved before its line: " << show.out;
}

/// Ctrl-Z (SIGTSTP) during a run: ignored, as in the console. A suspended run could neither vent nor
/// hold its tick, the valves as they were until someone continues it.
TEST(CliRun, CtrlZDoesNotSuspendARun) {
  setenv("XDG_DATA_HOME", testing::make_temp_dir("bellows-xdg").c_str(), 1);  // never the real home
  auto [pid, out] = spawn_bellows({"run", "--clock", "wall", "--speed", "5", "--iterations", "2", "--json"}, true);
  std::this_thread::sleep_for(std::chrono::milliseconds(500));  // past the start, in the first trial
  ASSERT_EQ(kill(pid, SIGTSTP), 0);
  int status = 0;
  ASSERT_EQ(waitpid(pid, &status, WUNTRACED), pid);  // before reading: the report (~5 kB) fits the pipe
  const bool suspended = WIFSTOPPED(status);
  if (suspended) {  // continued, so that the test ends either way
    kill(pid, SIGCONT);
    waitpid(pid, &status, 0);
  }
  const std::string text = read_all(out);
  EXPECT_FALSE(suspended) << "Ctrl-Z suspended the run, the valves as they were";
  ASSERT_TRUE(WIFEXITED(status));
  EXPECT_EQ(WEXITSTATUS(status), 0);
  EXPECT_EQ(nlohmann::json::parse(text)["iterations"].size(), 3u);
}

}  // namespace
}  // namespace bellows
