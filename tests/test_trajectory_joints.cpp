// Trajectories with one column per joint (issue 14, ../shared/spec/multi-joint.md section 3): the
// library's paper2 and paper3, the CSV files `time_s,q1_deg,...` both ways, and the single-joint
// trajectories exactly as they were.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "app/trajectory_file.hpp"
#include "engine/base/errors.hpp"
#include "engine/trial/trajectory.hpp"
#include "tests/process_runner.hpp"
#include "tests/test_support.hpp"

namespace bellows {
namespace {

constexpr double kJointDeg = std::numbers::pi / 180.0;
constexpr double kSample_s = 0.02;

double deg_at(const Trajectory& t, int joint, double time_s) {
  return t.joint(joint)(std::lround(time_s / t.sample_time_s)) / kJointDeg;
}

TEST(TrajectoryJoints, SingleJointLibraryKeepsItsNumbers) {
  // The moves the library held before it learned joints, written out: the same doubles, bit for bit.
  const Trajectory paper = library_trajectory("paper", kSample_s);
  const Trajectory paper_before = trajectory_from_moves("paper", 0.0,
                                                        {{0.6, 0, 30, 0.2, 12000.0},
                                                         {1.6, 30, -30, 0.2, 12000.0},
                                                         {2.6, -30, 30, 0.2, 12000.0},
                                                         {3.6, 30, -30, 0.2, 12000.0},
                                                         {4.6, -30, 30, 0.2, 12000.0},
                                                         {5.6, 30, 0, 0.2, 12000.0}},
                                                        8.0, kSample_s);
  EXPECT_EQ(paper.joints(), 1);
  EXPECT_TRUE(paper.angles_rad.size() == 1);
  EXPECT_EQ(paper.joint(0), paper_before.joint(0));
  const Trajectory steps = library_trajectory("steps", kSample_s);
  const Trajectory steps_before = trajectory_from_moves("steps", 0.0,
                                                        {{0.5, 0, 20, 0.3, 4000.0},
                                                         {2.0, 20, 40, 0.3, 4000.0},
                                                         {3.5, 40, -20, 0.3, 4000.0},
                                                         {5.0, -20, -40, 0.3, 4000.0},
                                                         {6.5, -40, 0, 0.3, 4000.0}},
                                                        10.0, kSample_s);
  EXPECT_EQ(steps.joint(0), steps_before.joint(0));
  EXPECT_EQ(library_trajectory("sine", kSample_s).joints(), 1);
  EXPECT_EQ(trajectory_library_joints("paper"), 1);
}

TEST(TrajectoryJoints, Paper2IsTheShouldersFourMovesAndThePapersElbow) {
  const Trajectory paper2 = library_trajectory("paper2", kSample_s);
  ASSERT_EQ(paper2.joints(), 2);
  EXPECT_EQ(trajectory_library_joints("paper2"), 2);
  EXPECT_EQ(paper2.learning_samples(), 400);                                    // 8 s at 50 Hz
  EXPECT_EQ(paper2.joint(1), library_trajectory("paper", kSample_s).joint(0));  // the elbow: the paper's
  // Shoulder 0 -> 20 -> -20 -> 20 -> 0 deg, 0.3 s moves starting at 0.6, 2.0, 3.4 and 4.8 s.
  const double starts_s[] = {0.6, 2.0, 3.4, 4.8};
  const Trajectory fine = library_trajectory("paper2", 0.005);  // half a move, 0.15 s, on the grid
  const double angles_deg[] = {0, 20, -20, 20, 0};
  for (int i = 0; i < 4; ++i) {
    EXPECT_NEAR(deg_at(paper2, 0, starts_s[i]), angles_deg[i], 1e-9) << "move " << i << " has not begun";
    EXPECT_NEAR(deg_at(paper2, 0, starts_s[i] + 0.3), angles_deg[i + 1], 1e-9) << "move " << i << " is done in 0.3 s";
    EXPECT_NEAR(deg_at(fine, 0, starts_s[i] + 0.15), 0.5 * (angles_deg[i] + angles_deg[i + 1]), 1e-9)
        << "move " << i << ": a symmetric trapezoid is half way at half time";
    const double still_moving = deg_at(paper2, 0, starts_s[i] + 0.28);
    EXPECT_GT(std::abs(still_moving - angles_deg[i + 1]), 0.01) << "move " << i << " takes the whole 0.3 s";
  }
  EXPECT_NEAR(deg_at(paper2, 0, 8.0), 0.0, 1e-12);
  // The paper's move shape (its trapezoid at 12000 deg/s^2 peak), the spec's moves written out.
  const Trajectory shoulder = trajectory_from_moves("shoulder", 0.0,
                                                    {{0.6, 0, 20, 0.3, 12000.0},
                                                     {2.0, 20, -20, 0.3, 12000.0},
                                                     {3.4, -20, 20, 0.3, 12000.0},
                                                     {4.8, 20, 0, 0.3, 12000.0}},
                                                    8.0, kSample_s);
  EXPECT_EQ(paper2.joint(0), shoulder.joint(0));
  const JointVector at_one_second = paper2.setpoint_rad(50);
  ASSERT_EQ(at_one_second.size(), 2);
  EXPECT_NEAR(at_one_second(0) / kJointDeg, 20.0, 1e-9);
  EXPECT_NEAR(at_one_second(1) / kJointDeg, 30.0, 1e-9);
}

TEST(TrajectoryJoints, Paper3AddsTheWristDoingThePapersMovesLater) {
  const Trajectory paper2 = library_trajectory("paper2", kSample_s);
  const Trajectory paper3 = library_trajectory("paper3", kSample_s);
  ASSERT_EQ(paper3.joints(), 3);
  EXPECT_EQ(trajectory_library_joints("paper3"), 3);
  EXPECT_EQ(paper3.joint(0), paper2.joint(0));
  EXPECT_EQ(paper3.joint(1), paper2.joint(1));
  // The wrist is the paper 0.3 s (15 samples) later, at +-30 deg.
  const Trajectory paper_trajectory = library_trajectory("paper", kSample_s);
  const Eigen::VectorXd& paper = paper_trajectory.joint(0);  // (a reference into a temporary would dangle)
  const Eigen::VectorXd& wrist = paper3.joint(2);
  for (Eigen::Index k = 0; k < wrist.size(); ++k) {
    EXPECT_NEAR(wrist(k), k < 15 ? 0.0 : paper(k - 15), 1e-9) << "sample " << k;
  }
  EXPECT_NEAR(wrist.maxCoeff() / kJointDeg, 30.0, 1e-9);
  EXPECT_NEAR(wrist.minCoeff() / kJointDeg, -30.0, 1e-9);
  EXPECT_NO_THROW(validate_trajectory(paper3, TrajectoryLimits{}));
}

TEST(TrajectoryJoints, TheLibraryListsItsJointCounts) {
  EXPECT_EQ(trajectory_library_summary(), "paper, steps, sine, paper2 (2 joints), paper3 (3 joints)");
  EXPECT_NE(trajectory_library_description("paper2").find("2 joints"), std::string::npos);
  EXPECT_NE(trajectory_library_description("paper3").find("3 joints"), std::string::npos);
  EXPECT_NE(testing::error_of([] { library_trajectory("paper4", kSample_s); }).find("paper3 (3 joints)"),
            std::string::npos);
}

TEST(TrajectoryJoints, JointCountsOutsideOneToFourAreRefused) {
  const JointMoves still{0.0, {}};
  EXPECT_EQ(trajectory_from_joint_moves("four", {still, still, still, still}, 1.0, kSample_s).joints(), 4);
  EXPECT_NE(testing::error_of([&] {
              trajectory_from_joint_moves("five", {still, still, still, still, still}, 1.0, kSample_s);
            }).find("5 joints: 1 to 4"),
            std::string::npos);
  EXPECT_THROW(trajectory_from_joint_moves("none", {}, 1.0, kSample_s), InputError);
  Trajectory ragged = library_trajectory("paper2", kSample_s);
  ragged.joint(1).conservativeResize(10);
  EXPECT_NE(testing::error_of([&] { validate_trajectory(ragged, {}); }).find("joint 2: has 10 samples"),
            std::string::npos);
}

TEST(TrajectoryJoints, TheTrajectoryMustHaveTheArmsJoints) {
  EXPECT_NO_THROW(require_driven_joints(library_trajectory("paper", kSample_s), ArmParameters{}));
  EXPECT_NO_THROW(require_driven_joints(library_trajectory("paper2", kSample_s), ArmParameters{"arm2"}));
  EXPECT_NO_THROW(require_driven_joints(library_trajectory("paper3", kSample_s), ArmParameters{"arm3"}));
  EXPECT_EQ(testing::error_of([] { require_driven_joints(library_trajectory("paper2", kSample_s), ArmParameters{}); }),
            "trajectory 'paper2' has 2 joints; the arm has 1 ([arm] preset)");
  EXPECT_EQ(
      testing::error_of([] { require_driven_joints(library_trajectory("paper", kSample_s), ArmParameters{"arm2"}); }),
      "trajectory 'paper' has 1 joint; the arm has 2 (arm2)");
  EXPECT_EQ(
      testing::error_of([] { require_driven_joints(library_trajectory("paper2", kSample_s), ArmParameters{"arm3"}); }),
      "trajectory 'paper2' has 2 joints; the arm has 3 (arm3)");
  EXPECT_EQ(testing::error_of([] { require_trajectory_joints(library_trajectory("paper", kSample_s), 3, "arm3"); }),
            "trajectory 'paper' has 1 joint; the arm has 3 (arm3)");
}

std::string joint_csv(const std::string& header, const std::vector<std::string>& rows) {
  std::string text = header + "\n";
  for (const std::string& row : rows) text += row + "\n";
  return text;
}

TEST(TrajectoryJointsCsv, ReadsOneColumnPerJoint) {
  const Trajectory t =
      parse_trajectory_csv(joint_csv("time_s,q1_deg,q2_deg,q3_deg", {"0,0,0,0", "0.02,1,-2,3", "0.04,2,-4,6"}),
                           "dir/arm3-wave.csv", kSample_s, {});
  EXPECT_EQ(t.name, "arm3-wave");
  ASSERT_EQ(t.joints(), 3);
  EXPECT_EQ(t.learning_samples(), 2);
  EXPECT_NEAR(t.joint(0)(2), 2.0 * kJointDeg, 1e-15);
  EXPECT_NEAR(t.joint(1)(2), -4.0 * kJointDeg, 1e-15);
  EXPECT_NEAR(t.joint(2)(1), 3.0 * kJointDeg, 1e-15);
  // q1_deg alone is one joint, like time_s,angle_deg; CR LF and a byte order mark as for one joint.
  EXPECT_EQ(parse_trajectory_csv("\xef\xbb\xbftime_s,q1_deg\r\n0,0\r\n0.02,1\r\n0.04,2\r\n", "one.csv", kSample_s, {})
                .joints(),
            1);
}

TEST(TrajectoryJointsCsv, WritesWhatItReadsBack) {
  const auto dir = testing::make_temp_dir("bellows-trajectory-joints");
  for (const std::string& name : trajectory_library_names()) {
    const Trajectory original = library_trajectory(name, kSample_s);
    const std::string text = trajectory_csv(original);
    const std::string header = text.substr(0, text.find('\n'));
    EXPECT_EQ(header, original.joints() == 1   ? "time_s,angle_deg"
                      : original.joints() == 2 ? "time_s,q1_deg,q2_deg"
                                               : "time_s,q1_deg,q2_deg,q3_deg")
        << name;
    write_trajectory_file(dir / (name + ".csv"), original);
    const Trajectory loaded = load_trajectory_file((dir / (name + ".csv")).string(), kSample_s, {});
    EXPECT_EQ(loaded.name, name);
    ASSERT_EQ(loaded.joints(), original.joints()) << name;
    for (int j = 0; j < original.joints(); ++j) {
      ASSERT_EQ(loaded.joint(j).size(), original.joint(j).size());
      EXPECT_LT((loaded.joint(j) - original.joint(j)).cwiseAbs().maxCoeff(), 1e-15) << name << " " << j;
    }
  }
  EXPECT_NE(trajectory_csv(library_trajectory("paper", kSample_s)).find("\n0.06,0\n"), std::string::npos)
      << "times read as a person writes them";
}

void expect_joint_csv_rejected(const std::string& text, const std::string& fragment) {
  const std::string error = testing::error_of([&] { parse_trajectory_csv(text, "bad.csv", kSample_s, {}); });
  EXPECT_NE(error.find(fragment), std::string::npos) << "wanted '" << fragment << "', got: " << error;
  EXPECT_NE(error.find("bad.csv"), std::string::npos) << error;
  EXPECT_EQ(error.find('\n'), std::string::npos) << "one line: " << error;
}

TEST(TrajectoryJointsCsv, RejectsBadFilesWithOneClearLine) {
  const std::string two = "time_s,q1_deg,q2_deg";
  expect_joint_csv_rejected(joint_csv(two, {"0,0,0", "0.02,1,1", "0.05,2,2"}), "sampling is not uniform");
  expect_joint_csv_rejected(joint_csv(two, {"0,0,0", "0.02,1", "0.04,2,2"}),
                            "line 3: expected 3 fields 'time_s,q1_deg,q2_deg', found 2");
  expect_joint_csv_rejected(joint_csv(two, {"0,0,0", "0.02,1,1,1", "0.04,2,2"}), "line 3: expected 3 fields");
  expect_joint_csv_rejected(joint_csv(two, {"0,0,0", "0.02,1,nan", "0.04,2,2"}),
                            "joint 2: angle at sample 1 is not a number");
  expect_joint_csv_rejected(joint_csv(two, {"0,0,0", "0.02,1,abc", "0.04,2,2"}), "line 3: 'abc' is not a number");
  expect_joint_csv_rejected(joint_csv(two, {"0,0,0", "0.02,1,120", "0.04,2,2"}),
                            "joint 2: angle 120 deg at t = 0.02 s is outside");
  expect_joint_csv_rejected(joint_csv(two, {"0,0,0"}), "too short");
  expect_joint_csv_rejected(joint_csv("time_s,q1_deg,q2_deg,q3_deg,q4_deg,q5_deg", {"0,0,0,0,0,0"}),
                            "line 1: 5 joint columns, at most 4 joints");
  expect_joint_csv_rejected(joint_csv("time_s,q1_deg,q3_deg", {"0,0,0"}),
                            "column 3 of the header must be 'q2_deg', found 'q3_deg'");
  expect_joint_csv_rejected(joint_csv("time_s,angle_deg,q2_deg", {"0,0,0"}),
                            "the header must be 'time_s,angle_deg' or");
  expect_joint_csv_rejected(joint_csv("time_s", {"0"}), "the header must be");
  expect_joint_csv_rejected(joint_csv("time_s,q1_deg,", {"0,0,"}), "column 3 of the header must be 'q2_deg', found ''");
}

}  // namespace
}  // namespace bellows
