// Trajectories with several joints as the binary shows them (issue 14): the help lists the library
// with joint counts, and `run` and the console, which drive one joint until the J-joint loop lands,
// refuse a multi-joint trajectory (library or file) with one line instead of using one column of it.
#include <algorithm>

#include <gtest/gtest.h>

#include "tests/process_runner.hpp"

namespace bellows {
namespace {

using testing::expect_refused_in_one_line;

TEST(CliTrajectories, HelpListsTheLibraryWithJointCounts) {
  for (const std::string command : {"run", "console"}) {
    const testing::ProcessResult help = testing::run_process(testing::kBellows + " " + command + " --help");
    EXPECT_EQ(help.exit_code, 0) << help.err;
    EXPECT_NE(help.out.find("paper2 (2 joints)"), std::string::npos) << help.out;
    EXPECT_NE(help.out.find("paper3 (3 joints)"), std::string::npos) << help.out;
  }
}

TEST(CliTrajectories, SingleJointRunAndConsoleRefuseSeveralJoints) {
  const auto dir = testing::make_temp_dir("bellows-cli-joints");
  expect_refused_in_one_line("run --no-save --iterations 1 --trajectory paper2",
                             "trajectory 'paper2' has 2 joints; the arm has 1 ([arm] preset)");
  expect_refused_in_one_line("run --no-save --iterations 1 --trajectory paper3", "trajectory 'paper3' has 3 joints");
  const auto file = testing::write_file(dir, "two.csv", "time_s,q1_deg,q2_deg\n0,0,0\n0.02,1,2\n0.04,2,4\n");
  expect_refused_in_one_line("run --no-save --iterations 1 --trajectory " + file.string(),
                             "trajectory 'two' has 2 joints");
  expect_refused_in_one_line("console --trajectory paper2", "trajectory 'paper2' has 2 joints");
  // A bad multi-joint file is refused for what is wrong with it, in one line too.
  const auto five = testing::write_file(dir, "five.csv", "time_s,q1_deg,q2_deg,q3_deg,q4_deg,q5_deg\n0,0,0,0,0,0\n");
  expect_refused_in_one_line("run --no-save --trajectory " + five.string(), "5 joint columns, at most 4 joints");
}

TEST(CliTrajectories, TheLibraryIsListedWithJointCounts) {
  const testing::ProcessResult listed = testing::run_process(testing::kBellows + " trajectories");
  ASSERT_EQ(listed.exit_code, 0) << listed.err;
  EXPECT_NE(listed.out.find("paper2        2     8.0 s      400"), std::string::npos) << listed.out;
  EXPECT_NE(listed.out.find("paper3        3     8.0 s      400"), std::string::npos) << listed.out;
  EXPECT_NE(listed.out.find("paper         1     8.0 s      400"), std::string::npos) << listed.out;
  EXPECT_NE(listed.out.find("steps         1    10.0 s      500"), std::string::npos) << listed.out;
}

TEST(CliTrajectories, ATrajectoryExportedAsCsvRunsAsTheLibrarysOwn) {
  const testing::ProcessResult paper2 = testing::run_process(testing::kBellows + " trajectories paper2");
  ASSERT_EQ(paper2.exit_code, 0) << paper2.err;
  EXPECT_EQ(paper2.out.rfind("time_s,q1_deg,q2_deg\n0,0,0\n", 0), 0u) << paper2.out.substr(0, 80);
  EXPECT_EQ(std::count(paper2.out.begin(), paper2.out.end(), '\n'), 402);  // the header and t = 0 .. 8 s

  const auto dir = testing::make_temp_dir("bellows-cli-export");
  const std::string file = (dir / "exported.csv").string();
  const testing::ProcessResult written =
      testing::run_process(testing::kBellows + " trajectories paper --output " + file);
  ASSERT_EQ(written.exit_code, 0) << written.err;
  EXPECT_TRUE(written.out.empty()) << written.out;
  auto first_rms = [](const std::string& trajectory) {
    const testing::ProcessResult run = testing::run_process(
        testing::kBellows + " run --no-save --json --quiet --iterations 0 --trajectory " + trajectory);
    EXPECT_EQ(run.exit_code, 0) << run.err;
    return testing::rms_sequence(nlohmann::json::parse(run.out)).at(0);
  };
  EXPECT_NEAR(first_rms(file), first_rms("paper"), 1e-9);
  expect_refused_in_one_line("trajectories --output " + file, "--output needs a trajectory");
  expect_refused_in_one_line("trajectories paper --output " + dir.string(), "is a directory: name a file in it");
  expect_refused_in_one_line("trajectories " + (dir / "missing.csv").string(), "cannot be read");
}

}  // namespace
}  // namespace bellows
