// Hostile configuration and command-line values, driven through the binary: each is refused with
// one line on stderr and exit status 2, before a session exists and without hanging; a signal during
// a long computation stops it with 128 + the signal. Every process runs under a deadline, so a
// hang fails the test instead of stalling the suite.
#include <signal.h>
#include <sys/stat.h>
#include <sys/wait.h>

#include <algorithm>
#include <chrono>
#include <thread>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "session_test_support.hpp"

namespace bellows {
namespace {

using testing::ProcessResult;
using testing::Spawned;
using testing::TempDir;
namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

constexpr auto kDeadline = std::chrono::seconds(60);  // far beyond any of these runs; a hang reaches it

// Reads both pipes until the process closes them or the deadline passes (then kills it: a hang).
ProcessResult finish(const Spawned& spawned, std::string out = {}, std::string err = {}) {
  ProcessResult result{-1, std::move(out), std::move(err)};
  pollfd fds[2] = {{spawned.out, POLLIN, 0}, {spawned.err, POLLIN, 0}};
  const auto deadline = Clock::now() + kDeadline;
  int open_pipes = 2;
  char buffer[4096];
  while (open_pipes > 0 && Clock::now() < deadline) {
    if (::poll(fds, 2, 200) <= 0) continue;
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
  if (open_pipes > 0) {
    ADD_FAILURE() << "still running after " << kDeadline.count() << " s: killed";
    ::kill(spawned.pid, SIGKILL);
    for (const pollfd& fd : fds) {
      if (fd.fd >= 0) ::close(fd.fd);
    }
  }
  int status = 0;
  ::waitpid(spawned.pid, &status, 0);
  result.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
  return result;
}

ProcessResult run(const std::vector<std::string>& args) { return finish(testing::spawn_bellows(args)); }

// Exit 2 and exactly one line on stderr, `bellows: ...` containing every fragment.
void expect_one_line_refusal(const ProcessResult& r, const std::vector<std::string>& fragments) {
  EXPECT_EQ(r.exit_code, 2) << r.err;
  EXPECT_EQ(r.err.rfind("bellows: ", 0), 0u) << r.err;
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << "one line: " << r.err;
  for (const std::string& fragment : fragments) EXPECT_NE(r.err.find(fragment), std::string::npos) << r.err;
}

TEST(HostileConfig, ADeeplyNestedFileIsRefusedNotACrash) {
  TempDir dir;
  std::string header = "[a";
  while (header.size() < 100000) header += ".a";
  const fs::path deep = dir / "deep.toml";
  testing::write_text(deep, header + ".b]\nx = 1\n");
  expect_one_line_refusal(run({"config", "--config", deep.string()}), {deep.string(), "nested deeper"});
  expect_one_line_refusal(run({"run", "--no-save", "--config", deep.string()}), {deep.string()});
}

TEST(HostileConfig, ADirectoryOrAFifoAsConfigIsRefused) {
  TempDir dir;
  expect_one_line_refusal(run({"config", "--config", dir.path().string()}),
                          {dir.path().string(), "not a regular file"});
  const fs::path fifo = dir / "fifo.toml";
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  expect_one_line_refusal(run({"config", "--config", fifo.string()}), {"not a regular file"});  // no hang
}

TEST(HostileConfig, TheIssuesValuesAreRefusedNamingFileAndKey) {
  TempDir dir;
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"[timing]\ntick_s = 1e-9\n", "[timing] tick_s"},
      {"[safety]\nblack_box_s = 1e9\n", "[safety] black_box_s"},
      {"[plant]\nintegration_step_s = 1e-12\n", "[plant] integration_step_s"},
      {"[ilc]\nprediction_grid_points = 100000\n", "[ilc] prediction_grid_points"},
      {"[safety]\nstale_ticks = 4294967299\n", "[safety] stale_ticks"},
      {"[timing]\nticks_per_sample = 4294967297\n", "[timing] ticks_per_sample"},
      {"[timing]\nsettle_s = 1e9\n", "[timing] settle_s"},
      {"[ilc]\nlaw = \"gradient\"\ngradient_step = 2.5\n", "[ilc] gradient_step"},
      {"[plant]\nfault = \"stuck-outlet\"\n", "[plant] fault"},
  };
  for (const auto& [toml, key] : cases) {
    const fs::path file = dir / "lab.toml";
    testing::write_text(file, toml);
    for (const char* command : {"run", "identify"}) {
      std::vector<std::string> args = {command, "--config", file.string()};
      if (std::string(command) == "run") args.push_back("--no-save");
      expect_one_line_refusal(run(args), {file.string(), key});
    }
  }
}

TEST(HostileCli, NumbersThatWouldWrapOrNeverEndAreRefused) {
  expect_one_line_refusal(run({"run", "--no-save", "--seed", "-1"}), {"--seed"});
  expect_one_line_refusal(run({"identify", "--seed", "-1"}), {"--seed"});
  expect_one_line_refusal(run({"io-sim", "--seed", "18446744073709551616"}), {"--seed"});
  for (const char* duration : {"nan", "inf", "-1", "1e400", "x"}) {
    expect_one_line_refusal(run({"io-sim", "--duration", duration}), {"--duration"});
  }
  expect_one_line_refusal(run({"console", "--exit-after", "nan"}), {"--exit-after"});
}

TEST(HostileCli, ABadLcmUrlIsRefusedBeforeASessionExists) {
  TempDir dir;
  const fs::path data = dir / "data";
  for (const char* url : {"udpm://300.1.1.1:7667", "udpm://239.255.76.67:99999", "udpm://10.0.0.1:7667",
                          "udpm://239.255.76.67:7667?ttl=x", "bogus://x", "239.255.76.67:7667", "memq://x"}) {
    expect_one_line_refusal(run({"run", "--lcm", url, "--iterations", "0", "--data-dir", data.string()}), {"--lcm"});
    EXPECT_FALSE(fs::exists(data) && !fs::is_empty(data)) << url << ": a session was created";
    expect_one_line_refusal(run({"io-sim", "--lcm", url, "--duration", "0.1"}), {"--lcm"});
  }
}

TEST(HostileManifest, BadValuesInASavedSessionAreRefusedByShowAndResumeWithoutHanging) {
  TempDir dir;
  const std::string data = (dir / "data").string();
  testing::write_short_run_files(dir.path());
  ASSERT_EQ(run({"run", "--trajectory", (dir / "short.csv").string(), "--config", (dir / "short.toml").string(),
                 "--iterations", "1", "--data-dir", data, "--name", "s"})
                .exit_code,
            0);
  const fs::path manifest = fs::path(data) / "s" / "manifest.json";
  const std::string original = testing::read_text(manifest);
  const std::vector<std::tuple<std::string, std::string, nlohmann::json>> cases = {
      {"timing", "tick_s", 1e-9},
      {"safety", "black_box_s", 1e9},
      {"plant", "integration_step_s", 1e-12},
      {"ilc", "prediction_grid_points", 100000},
      {"safety", "stale_ticks", 4294967299LL},
      {"timing", "ticks_per_sample", 4294967297LL},
      {"timing", "settle_s", 1e9},
      {"timing", "settle_max_s", 1e9},
      {"timing", "settle_tolerance_deg", 0.0},
  };
  for (const auto& [section, key, value] : cases) {
    nlohmann::ordered_json json = nlohmann::ordered_json::parse(original);
    json["configuration"][section][key] = value;
    testing::write_text(manifest, json.dump(2));
    expect_one_line_refusal(run({"sessions", "show", data + "/s"}), {"manifest.json", key});
    expect_one_line_refusal(run({"run", "--resume", data + "/s", "--iterations", "1"}), {"manifest.json", key});
  }
  // A trial far longer than the configuration allows is refused before its files are read.
  nlohmann::ordered_json json = nlohmann::ordered_json::parse(original);
  json["trajectory"]["learning_samples"] = 50'000'000;
  testing::write_text(manifest, json.dump(2));
  expect_one_line_refusal(run({"sessions", "show", data + "/s"}),
                          {"manifest.json", "learning_samples", "ticks per trial"});
  expect_one_line_refusal(run({"run", "--resume", data + "/s", "--iterations", "1"}), {"learning_samples"});
  // The refusals held no lock: the repaired session resumes.
  testing::write_text(manifest, original);
  const ProcessResult resumed = run({"run", "--resume", data + "/s", "--iterations", "1"});
  EXPECT_EQ(resumed.exit_code, 0) << resumed.err;
}

// Reads stderr until `text` appears (or the deadline passes); returns what was read.
std::string read_until_or_deadline(int fd, const std::string& text) {
  std::string got;
  char buffer[4096];
  const auto deadline = Clock::now() + kDeadline;
  pollfd pfd{fd, POLLIN, 0};
  while (got.find(text) == std::string::npos && Clock::now() < deadline) {
    if (::poll(&pfd, 1, 200) <= 0) continue;
    const ssize_t n = ::read(fd, buffer, sizeof buffer);
    if (n <= 0) break;
    got.append(buffer, static_cast<std::size_t>(n));
  }
  return got;
}

TEST(HostileSignals, SigintDuringALongIdentificationStopsItWith130) {
  TempDir dir;
  const fs::path config = dir / "long.toml";
  testing::write_text(config, "[identify]\nduration_s = 600.0\n");  // minutes of simulation
  for (const int signal_number : {SIGINT, SIGTERM}) {
    const Spawned spawned = testing::spawn_bellows({"identify", "--config", config.string(), "--json"});
    std::string err = read_until_or_deadline(spawned.err, "identification trial");
    ASSERT_NE(err.find("identification trial"), std::string::npos) << err;
    std::this_thread::sleep_for(std::chrono::milliseconds(300));  // inside the trial's simulation
    ::kill(spawned.pid, signal_number);
    const ProcessResult r = finish(spawned, {}, err);
    EXPECT_EQ(r.exit_code, 128 + signal_number) << r.err;
    EXPECT_NE(r.err.find("stopped by a signal"), std::string::npos) << r.err;
    EXPECT_TRUE(r.out.empty()) << "no report for a stopped identification: " << r.out;
  }
}

}  // namespace
}  // namespace bellows
