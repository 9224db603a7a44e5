// Runs a shell command for end-to-end tests and captures its exit status, stdout and stderr.
// XDG_DATA_HOME points into a fresh temporary directory so no test writes into a real home.
#pragma once

#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <mutex>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

namespace bellows::testing {

struct ProcessResult {
  int exit_code = -1;
  std::string out;
  std::string err;
  bool hung = false;  // killed by a hang guard (run_bellows()): a regression that blocks fails, never hangs the suite
};

/// The bellows binary under test.
inline const std::string kBellows = BELLOWS_BINARY;

/// The directories make_temp_dir made, removed when the test process that made them ends: a run of
/// the suite left ~800 in /tmp. Kept when a test of that process failed (to look at what it wrote)
/// or when BELLOWS_KEEP_TEST_DIRS is set; a forked child's exit removes nothing (the owner's pid).
class TempDirsOfThisProcess {
 public:
  static TempDirsOfThisProcess& instance() {
    static TempDirsOfThisProcess dirs;
    return dirs;
  }
  void add(const std::filesystem::path& dir) {
    const std::lock_guard<std::mutex> lock(mutex_);
    dirs_.push_back(dir);
  }
  ~TempDirsOfThisProcess() {
    if (::getpid() != owner_ || std::getenv("BELLOWS_KEEP_TEST_DIRS") != nullptr ||
        ::testing::UnitTest::GetInstance()->Failed())
      return;
    std::error_code error;  // best effort: a directory a test's child still writes to may resist
    for (const std::filesystem::path& dir : dirs_) std::filesystem::remove_all(dir, error);
  }

 private:
  // Touching gtest's UnitTest first makes it outlive this registry (statics end in reverse order),
  // so the destructor may ask it whether a test failed, even if a directory is made before main.
  TempDirsOfThisProcess() { ::testing::UnitTest::GetInstance(); }
  const pid_t owner_ = ::getpid();
  std::mutex mutex_;
  std::vector<std::filesystem::path> dirs_;
};

inline std::filesystem::path make_temp_dir(const std::string& prefix) {
  std::string pattern = (std::filesystem::temp_directory_path() / (prefix + "-XXXXXX")).string();
  if (mkdtemp(pattern.data()) == nullptr) throw std::runtime_error("mkdtemp failed");
  TempDirsOfThisProcess::instance().add(pattern);
  return pattern;
}

inline ProcessResult run_process(const std::string& command) {
  static const std::filesystem::path scratch = make_temp_dir("bellows-test");
  const std::filesystem::path err_path = scratch / "stderr.txt";
  const std::string full =
      "XDG_DATA_HOME='" + (scratch / "xdg").string() + "' " + command + " 2>'" + err_path.string() + "'";
  ProcessResult result;
  FILE* pipe = popen(full.c_str(), "r");
  if (pipe == nullptr) return result;
  std::array<char, 4096> buffer{};
  std::size_t n;
  while ((n = fread(buffer.data(), 1, buffer.size(), pipe)) > 0) result.out.append(buffer.data(), n);
  const int status = pclose(pipe);
  result.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
  std::ifstream err(err_path);
  std::stringstream text;
  text << err.rdbuf();
  result.err = text.str();
  return result;
}

inline std::filesystem::path write_file(const std::filesystem::path& dir, const std::string& name,
                                        const std::string& text) {
  const std::filesystem::path path = dir / name;
  std::ofstream(path) << text;
  return path;
}

/// `bellows ARGS` (stdin from /dev/null, no terminal) is refused: exit `status`, nothing on stdout,
/// and one line of its own on stderr that contains `fragment`.
inline void expect_refused_in_one_line(const std::string& args, const std::string& fragment, int status = 2) {
  const ProcessResult result = run_process(kBellows + " " + args + " < /dev/null");
  EXPECT_EQ(result.exit_code, status) << args << "\n" << result.err;
  EXPECT_TRUE(result.out.empty()) << args << ": " << result.out;
  EXPECT_NE(result.err.find(fragment), std::string::npos) << args << ": " << result.err;
  EXPECT_EQ(std::count(result.err.begin(), result.err.end(), '\n'), 1) << args << ": " << result.err;
  EXPECT_EQ(result.err.rfind("bellows: ", 0), 0u) << args << ": " << result.err;
}

/// The RMS of every iteration of a `bellows run --json` report, in order.
inline std::vector<double> rms_sequence(const nlohmann::json& report) {
  std::vector<double> rms;
  for (const auto& it : report.at("iterations")) rms.push_back(it.at("rms_deg").get<double>());
  return rms;
}

}  // namespace bellows::testing
