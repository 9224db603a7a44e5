// The command line keeps the conventions people know: --version, help without internal codes or
// build paths, and options that would do nothing refused with one line (exit 2), never ignored.
#include <algorithm>

#include <gtest/gtest.h>

#include "sessions/session.hpp"
#include "tests/process_runner.hpp"

namespace bellows {
namespace {

using testing::expect_refused_in_one_line;

using testing::run_process;

testing::ProcessResult bellows(const std::string& args) {
  return run_process(std::string(BELLOWS_BINARY) + " " + args + " < /dev/null");
}

TEST(CliConventions, VersionIsTheOneSessionsRecord) {
  const auto result = bellows("--version");
  EXPECT_EQ(result.exit_code, 0) << result.err;
  EXPECT_EQ(result.out, "bellows " + program_version() + "\n");
  EXPECT_FALSE(program_version().empty());
}

const char* const kCommands[] = {"",
                                 "run",
                                 "sessions",
                                 "sessions list",
                                 "sessions show",
                                 "sessions export",
                                 "sessions rm",
                                 "sessions rename",
                                 "sessions plot",
                                 "io-sim",
                                 "t7-sim",
                                 "console",
                                 "config",
                                 "identify",
                                 "rig",
                                 "rig check",
                                 "trajectories"};

TEST(CliConventions, HelpShowsWordsNotCodesOrBuildPaths) {
  for (const std::string command : kCommands) {
    const auto result = bellows(command + " --help");
    EXPECT_EQ(result.exit_code, 0) << command << ": " << result.err;
    EXPECT_NE(result.out.find("Usage"), std::string::npos) << command;
    EXPECT_EQ(result.out.find("->"), std::string::npos) << command << ":\n" << result.out;
    EXPECT_EQ(result.out.find("ENUM"), std::string::npos) << command << ":\n" << result.out;
    EXPECT_EQ(result.out.find(BELLOWS_SOURCE_DIR), std::string::npos) << command << ":\n" << result.out;
  }
  for (const std::string command : {"run", "io-sim", "console", "identify", "rig check"}) {
    EXPECT_NE(bellows(command + " --help").out.find("enforce|off|try"), std::string::npos) << command;
  }
}

// `bellows` alone is the console, so options without a command are the console's: each is checked
// as `bellows console` checks it (the console's own refusals), and one it does not know is refused.
TEST(CliConventions, OptionsWithoutACommandAreTheConsoles) {
  expect_refused_in_one_line("--exit-after nan", "--exit-after: must be a finite number");
  expect_refused_in_one_line("--speed 3", "--speed: 3 not in");
  expect_refused_in_one_line("--seed 7 --frobnicate", "--frobnicate");
  const auto console = bellows("--speed 10 --help");
  EXPECT_EQ(console.exit_code, 0) << console.err;
  EXPECT_NE(console.out.find("--stop-after-rises"), std::string::npos) << console.out;
  EXPECT_EQ(bellows("--help").out.find("--stop-after-rises"), std::string::npos);
}

TEST(CliConventions, TheWordsStillChooseTheMode) {
  expect_refused_in_one_line("run --rt sometimes", "--rt");
  EXPECT_EQ(bellows("run --rt OFF --iterations 0 --no-save --trajectory steps").exit_code, 0);
}

TEST(CliConventions, SpeedOnTheSimulatedClockIsRefused) {
  expect_refused_in_one_line("run --speed 10 --no-save", "--speed is for --clock wall");
  expect_refused_in_one_line("run --clock sim --speed max --no-save", "--speed is for --clock wall");
}

TEST(CliConventions, AMissingDataDirectoryIsRefusedNotEmpty) {
  const auto dir = testing::make_temp_dir("bellows-cli-conventions");
  const std::string missing = (dir / "typo").string();
  for (const std::string command : {"sessions list", "sessions show x", "sessions export x", "sessions rm --yes x",
                                    "sessions rename x y", "sessions plot x"}) {
    expect_refused_in_one_line(command + " --data-dir " + missing, "no such directory");
  }
  const auto file = testing::write_file(dir, "a-file", "text");
  expect_refused_in_one_line("sessions list --data-dir " + file.string(), "not a directory");
  const auto empty = bellows("sessions list --data-dir " + dir.string());
  EXPECT_EQ(empty.exit_code, 0) << empty.err;
  EXPECT_NE(empty.out.find("no sessions"), std::string::npos) << empty.out;
}

TEST(CliConventions, ConfigErrorsNameTheFileAndSayWhyItCannotBeRead) {
  const auto dir = testing::make_temp_dir("bellows-cli-config-errors");
  for (const std::string& text : {std::string("[ilc]\nlaw = \"pd\"\npd_q_cutoff_hz = 30.0\n"),
                                  std::string("[ilc]\nlaw = \"noilc-dense\"\ns = 0.0\nw = 0.0\n"),
                                  std::string("[ilc]\nlaw = \"bogus\"\n"), std::string("[ilc]\nm = -1.0\n")}) {
    const auto file = testing::write_file(dir, "ilc.toml", text);
    expect_refused_in_one_line("run --no-save --config " + file.string(), "config " + file.string() + ": [ilc]");
  }
  expect_refused_in_one_line("config --config " + (dir / "missing.toml").string(),
                             "missing.toml: cannot be read: No such file");
  expect_refused_in_one_line("config --config " + dir.string(), "is a directory");
}

}  // namespace
}  // namespace bellows
