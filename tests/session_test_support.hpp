// Helpers shared by the session tests: temporary directories, running the bellows binary, and a
// short simulated session built in-process (real records, a few milliseconds per trial).
#pragma once

#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "devices/simulated_arm.hpp"
#include "engine/model/arm_model.hpp"
#include "engine/rt/engine_core.hpp"
#include "engine/rt/engine_driver.hpp"
#include "engine/config/learning_law_factory.hpp"
#include "engine/operator/learning_session.hpp"
#include "sessions/session.hpp"
#include "tests/process_runner.hpp"

namespace bellows::testing {

class TempDir {
 public:
  TempDir() {
    std::string pattern = (std::filesystem::temp_directory_path() / "bellows-test-XXXXXX").string();
    if (::mkdtemp(pattern.data()) == nullptr) throw std::runtime_error("mkdtemp failed");
    path_ = pattern;
  }
  ~TempDir() {
    std::error_code error;
    std::filesystem::remove_all(path_, error);
  }
  TempDir(const TempDir&) = delete;
  TempDir& operator=(const TempDir&) = delete;
  const std::filesystem::path& path() const { return path_; }
  std::filesystem::path operator/(const std::string& name) const { return path_ / name; }

 private:
  std::filesystem::path path_;
};

inline void write_text(const std::filesystem::path& path, const std::string& text) {
  std::ofstream out(path, std::ios::binary);
  out << text;
}

inline std::string read_text(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

/// How long run_bellows() waits before it kills the process and reports it hung. A hang guard,
/// not a speed check: every command it runs takes well under a second on an idle machine.
inline constexpr int kHangGuard_ms = 120000;

/// A bellows process running in the background, its stdout and stderr on pipes.
struct Spawned {
  pid_t pid = -1;
  int out = -1, err = -1;
};

/// Starts the bellows binary with `args`; `env` entries "NAME=value" are set, "NAME" unset.
inline Spawned spawn_bellows(const std::vector<std::string>& args, const std::vector<std::string>& env = {}) {
  int out_pipe[2], err_pipe[2];
  if (::pipe2(out_pipe, O_CLOEXEC) != 0 || ::pipe2(err_pipe, O_CLOEXEC) != 0) throw std::runtime_error("pipe failed");
  std::vector<std::string> arguments{BELLOWS_BINARY};
  arguments.insert(arguments.end(), args.begin(), args.end());
  std::vector<char*> argv;
  for (std::string& arg : arguments) argv.push_back(arg.data());
  argv.push_back(nullptr);
  const pid_t pid = ::fork();
  if (pid == 0) {
    ::dup2(out_pipe[1], 1);
    ::dup2(err_pipe[1], 2);
    for (const std::string& entry : env) ::putenv(const_cast<char*>(entry.c_str()));  // glibc: no '=' unsets
    ::execv(BELLOWS_BINARY, argv.data());
    ::_exit(127);
  }
  ::close(out_pipe[1]);
  ::close(err_pipe[1]);
  return {pid, out_pipe[0], err_pipe[0]};
}

/// Runs the bellows binary to completion, collecting its output; kills it (and sets `hung`) if it
/// has not finished after `guard_ms`.
inline ProcessResult run_bellows(const std::vector<std::string>& args, const std::vector<std::string>& env = {},
                                 int guard_ms = kHangGuard_ms) {
  const Spawned spawned = spawn_bellows(args, env);
  const pid_t pid = spawned.pid;
  int out_pipe[2] = {spawned.out, -1}, err_pipe[2] = {spawned.err, -1};
  ProcessResult result;
  pollfd fds[2] = {{out_pipe[0], POLLIN, 0}, {err_pipe[0], POLLIN, 0}};
  int open_pipes = 2;
  char buffer[4096];
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::milliseconds(guard_ms);
  while (open_pipes > 0) {
    const auto left =
        std::chrono::duration_cast<std::chrono::milliseconds>(deadline - std::chrono::steady_clock::now());
    if (left.count() <= 0 && !result.hung) {
      result.hung = true;
      ::kill(pid, SIGKILL);  // its pipes close: the loop ends
    }
    if (::poll(fds, 2, result.hung ? -1 : static_cast<int>(left.count()) + 1) < 0) continue;
    for (int i = 0; i < 2; ++i) {
      if (fds[i].fd < 0 || fds[i].revents == 0) continue;
      const ssize_t got = ::read(fds[i].fd, buffer, sizeof buffer);
      if (got > 0) {
        (i == 0 ? result.out : result.err).append(buffer, static_cast<std::size_t>(got));
      } else {
        ::close(fds[i].fd);
        fds[i].fd = -1;
        --open_pipes;
      }
    }
  }
  int status = 0;
  ::waitpid(pid, &status, 0);
  result.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
  return result;
}

/// A configuration with a short settle, so trials take milliseconds.
inline Configuration short_configuration() {
  Configuration config;
  config.timing.settle_s = 0.05;
  return config;
}

/// 0.5 s, one move from 0 to 20 deg: 25 learning samples at 50 Hz.
inline Trajectory short_trajectory(double sample_time_s) {
  return trajectory_from_moves("short", 0.0, {{0.1, 0.0, 20.0, 0.2, 12000.0}}, 0.5, sample_time_s);
}

/// The same trajectory as a CSV file for `bellows run --trajectory`, and the matching TOML config.
inline void write_short_run_files(const std::filesystem::path& directory) {
  std::string csv = "time_s,angle_deg\n";
  const Trajectory trajectory = short_trajectory(0.02);
  for (Eigen::Index k = 0; k <= trajectory.learning_samples(); ++k) {
    std::ostringstream row;
    row.precision(17);
    row << static_cast<double>(k) * 0.02 << "," << trajectory.joint(0)(k) * 180.0 / 3.141592653589793 << "\n";
    csv += row.str();
  }
  write_text(directory / "short.csv", csv);
  write_text(directory / "short.toml", "[timing]\nsettle_s = 0.05\n");
}

/// A session simulated in-process, as `bellows run` would save it (without the device state JSON
/// of the app: a stand-in object carries the arm's time).
inline Session simulate_session(int trials, const std::string& name = "simulated") {
  const Configuration config = short_configuration();
  const Trajectory trajectory = short_trajectory(config.timing.sample_s());
  const DiscreteArmModel model = discretize_arm_model(config.model, config.timing.sample_s());
  const auto law = make_learning_law(config, model, trajectory.learning_samples());
  SimulatedArm arm(config.plant, 7);
  EngineCore core(arm, config.controller, config.timing, config.safety);
  SimulatedClock clock(core, arm);
  LearningSession learning(clock, *law, trajectory, config.timing, config.controller);

  Session session;
  SessionManifest& m = session.manifest;
  m.program_version = program_version();
  m.name = name;
  m.device = arm.name();
  m.device_info = {{"seed", 7}};
  m.started_utc = utc_now();
  m.updated_utc = m.started_utc;
  m.configuration = config;
  m.trajectory_name = trajectory.name;
  m.trajectory_samples = trajectory.learning_samples();
  m.events.push_back({m.started_utc, 0, "start", "simulated in a test"});
  session.trajectory = trajectory;
  for (int i = 0; i < trials; ++i) {
    const IterationSummary summary = learning.run_trial();
    learning.learn();
    session.iterations.push_back({learning.last_record(), learning.correction_bar()});
    m.iterations.push_back({summary, utc_now()});
    m.resume = ResumeState{core.control().state(), {{"time_s", arm.state().time_s}}, clock.ticks()};
  }
  return session;
}

}  // namespace bellows::testing
