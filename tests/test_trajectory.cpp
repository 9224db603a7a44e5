#include <gtest/gtest.h>

#include <numbers>

#include "app/trajectory_file.hpp"
#include "engine/base/errors.hpp"
#include "engine/trial/trajectory.hpp"

namespace bellows {
namespace {

constexpr double kDeg = std::numbers::pi / 180.0;

TEST(TrapezoidalMove, PaperMoveHasTheSpecsPhasesAndCruiseSpeed) {
  const TrapezoidalMove move{0.0, 0.0, 60.0, 0.2, 12000.0};
  // Acceleration phase t_a with a t_a (T - t_a) = 60 deg: ~29.3 ms, cruise ~351 deg/s.
  const double t_a = 0.5 * (0.2 - std::sqrt(0.04 - 4.0 * 60.0 / 12000.0));
  EXPECT_NEAR(t_a, 0.0293, 1e-4);
  const double h = 1e-6;
  const double cruise =
      (trapezoidal_move_angle_deg(move, 0.1 + h) - trapezoidal_move_angle_deg(move, 0.1 - h)) / (2 * h);
  EXPECT_NEAR(cruise, 351.0, 1.0);
  const double accel = (trapezoidal_move_angle_deg(move, 0.01 + h) - 2 * trapezoidal_move_angle_deg(move, 0.01) +
                        trapezoidal_move_angle_deg(move, 0.01 - h)) /
                       (h * h);
  EXPECT_NEAR(accel, 12000.0, 50.0);
  EXPECT_DOUBLE_EQ(trapezoidal_move_angle_deg(move, -1.0), 0.0);
  EXPECT_NEAR(trapezoidal_move_angle_deg(move, 0.1), 30.0, 1e-9);  // symmetric profile
  EXPECT_DOUBLE_EQ(trapezoidal_move_angle_deg(move, 0.2), 60.0);
  EXPECT_DOUBLE_EQ(trapezoidal_move_angle_deg(move, 5.0), 60.0);
}

TEST(TrapezoidalMove, ImpossibleMoveIsRejected) {
  EXPECT_THROW(trapezoidal_move_angle_deg({0.0, 0.0, 200.0, 0.2, 12000.0}, 0.1), InputError);
}

TEST(TrajectoryLibrary, PaperFollowsSection6) {
  const Trajectory paper = library_trajectory("paper", 0.02);
  EXPECT_EQ(paper.learning_samples(), 400);
  EXPECT_NEAR(paper.duration_s(), 8.0, 1e-12);
  auto at = [&](double t) { return paper.joint(0)(std::lround(t / 0.02)) / kDeg; };
  EXPECT_DOUBLE_EQ(at(0.0), 0.0);
  EXPECT_NEAR(at(0.6), 0.0, 1e-9);
  EXPECT_NEAR(at(1.0), 30.0, 1e-9);
  EXPECT_NEAR(at(2.0), -30.0, 1e-9);
  EXPECT_NEAR(at(3.0), 30.0, 1e-9);
  EXPECT_NEAR(at(5.0), 30.0, 1e-9);
  EXPECT_NEAR(at(6.0), 0.0, 1e-9);
  EXPECT_NEAR(at(8.0), 0.0, 1e-9);
}

TEST(TrajectoryLibrary, EveryEntryIsValidAndUnknownNamesAreRejected) {
  for (const std::string& name : trajectory_library_names()) {
    const Trajectory t = library_trajectory(name, 0.02);
    EXPECT_NO_THROW(validate_trajectory(t, TrajectoryLimits{})) << name;
    EXPECT_FALSE(trajectory_library_description(name).empty());
    EXPECT_GT(t.joint(0).cwiseAbs().maxCoeff(), 10.0 * kDeg) << name;
  }
  EXPECT_THROW(library_trajectory("nope", 0.02), InputError);
}

std::string csv(const std::vector<std::pair<double, double>>& rows, const std::string& header = "time_s,angle_deg") {
  std::string text = header + "\n";
  for (const auto& [t, a] : rows) text += std::to_string(t) + "," + std::to_string(a) + "\n";
  return text;
}

TEST(TrajectoryCsv, ParsesAUniformFile) {
  const Trajectory t =
      parse_trajectory_csv(csv({{0.0, 0.0}, {0.02, 1.0}, {0.04, 2.5}, {0.06, 3.0}}), "dir/ramp.csv", 0.02, {});
  EXPECT_EQ(t.name, "ramp");
  EXPECT_EQ(t.learning_samples(), 3);
  EXPECT_NEAR(t.joint(0)(2), 2.5 * kDeg, 1e-12);
}

void expect_csv_rejected(const std::string& text, const std::string& fragment) {
  try {
    parse_trajectory_csv(text, "bad.csv", 0.02, {});
    FAIL() << "accepted: " << fragment;
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find(fragment), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("bad.csv"), std::string::npos) << e.what();
  }
}

TEST(TrajectoryCsv, RejectsBadFilesWithAClearMessage) {
  expect_csv_rejected(csv({{0.0, 0.0}, {0.02, 1.0}, {0.04, 2.0}}, "t,angle"), "header");
  expect_csv_rejected(csv({{0.0, 0.0}, {0.02, 1.0}, {0.05, 2.0}}), "not uniform");
  expect_csv_rejected(csv({{0.01, 0.0}, {0.03, 1.0}, {0.05, 2.0}}), "not uniform");
  expect_csv_rejected("time_s,angle_deg\n0,0\n0.02,nan\n0.04,1\n", "not a number");
  expect_csv_rejected("time_s,angle_deg\n0,0\n0.02,abc\n0.04,1\n", "line 3");
  expect_csv_rejected("time_s,angle_deg\n0,0\n0.02,1,2\n0.04,1\n", "two fields");
  expect_csv_rejected(csv({{0.0, 0.0}, {0.02, 120.0}, {0.04, 2.0}}), "joint range");
  expect_csv_rejected(csv({{0.0, 0.0}}), "too short");
  expect_csv_rejected("", "header");
}

}  // namespace
}  // namespace bellows
