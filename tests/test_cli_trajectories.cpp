// Trajectories with several joints as the binary shows them (issue 14): the help lists the library
// with joint counts, and `run` and the console, which drive one joint until the J-joint loop lands,
// refuse a multi-joint trajectory (library or file) with one line instead of using one column of it.
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
  expect_refused_in_one_line("run --no-save --iterations 1 --trajectory " + file.string(), "trajectory 'two' has 2 joints");
  expect_refused_in_one_line("console --trajectory paper2", "trajectory 'paper2' has 2 joints");
  // A bad multi-joint file is refused for what is wrong with it, in one line too.
  const auto five = testing::write_file(dir, "five.csv", "time_s,q1_deg,q2_deg,q3_deg,q4_deg,q5_deg\n0,0,0,0,0,0\n");
  expect_refused_in_one_line("run --no-save --trajectory " + five.string(), "5 joint columns, at most 4 joints");
}

}  // namespace
}  // namespace bellows
