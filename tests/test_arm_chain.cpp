// The simulated J-joint arm's mechanics (../shared/spec/multi-joint.md sections 1, 2): presets with the
// spec's numbers, the rigid-body terms against the textbook two-link formulas, energy conservation,
// gravity, the single-joint reduction, holding, hard stops, determinism and resuming.
#include <gtest/gtest.h>

#include <numbers>
#include <random>

#include "engine/model/arm_chain.hpp"
#include "engine/base/errors.hpp"
#include "engine/base/parameters.hpp"

namespace bellows {
namespace {

constexpr double kG = 9.81;

JointVector joints_vector(std::initializer_list<double> values) {
  JointVector v(static_cast<Eigen::Index>(values.size()));
  Eigen::Index i = 0;
  for (double x : values) v(i++) = x;
  return v;
}

/// A chain without damping, creep or reachable stops: only the rigid body and the springs.
ChainParameters conservative(ChainParameters chain) {
  for (ChainLink& l : chain.links) {
    l.damping_ratio = 0.0;
    l.creep_gain = 0.0;
    l.hard_stop_deg = 1.0e4;
  }
  return chain;
}

/// One link whose inertia about the joint is K / w0^2 of the single-joint arm (the paper's elbow).
ChainParameters single_joint_chain(const PlantParameters& plant) {
  ChainParameters chain;
  chain.joints = 1;
  ChainLink& l = chain.links[0];
  l.mass_kg = 0.10;
  l.length_m = 0.30;
  l.center_of_mass_m = 0.15;
  l.stiffness_Nm_per_rad = 0.60;
  l.kappa_rad_per_bar = plant.kappa_rad_per_bar;
  l.omega0_straight_rad_per_s = plant.omega0_rad_per_s;
  l.damping_ratio = plant.damping;
  l.creep_gain = plant.creep_gain;
  l.creep_tau_s = plant.creep_tau_s;
  l.hard_stop_deg = plant.hard_stop_deg;
  const double joint_inertia = l.stiffness_Nm_per_rad / (plant.omega0_rad_per_s * plant.omega0_rad_per_s);
  l.inertia_kg_m2 = joint_inertia - l.mass_kg * l.center_of_mass_m * l.center_of_mass_m;
  chain.hard_stop_stiffness_per_s2 = plant.hard_stop_stiffness_per_s2;
  chain.hard_stop_damping_per_s = plant.hard_stop_damping_per_s;
  chain.gravity = false;
  return chain;
}

TEST(ArmChain, PresetsCarryTheSpecsTables) {
  const ChainParameters arm2 = chain_preset("arm2");
  ASSERT_EQ(arm2.joints, 2);
  EXPECT_TRUE(arm2.gravity);
  const ChainLink& shoulder = arm2.links[0];
  EXPECT_EQ(shoulder.mass_kg, 0.40);
  EXPECT_EQ(shoulder.length_m, 0.25);
  EXPECT_EQ(shoulder.center_of_mass_m, 0.125);
  EXPECT_EQ(shoulder.inertia_kg_m2, 2.08e-3);
  EXPECT_EQ(shoulder.tip_mass_kg, 0.30);
  EXPECT_EQ(shoulder.stiffness_Nm_per_rad, 2.81);
  EXPECT_EQ(shoulder.kappa_rad_per_bar, 5.0);
  EXPECT_EQ(shoulder.omega0_straight_rad_per_s, 8.0);
  EXPECT_EQ(shoulder.damping_ratio, 0.31);
  const ChainLink& elbow = arm2.links[1];
  EXPECT_EQ(elbow.mass_kg, 0.10);
  EXPECT_EQ(elbow.length_m, 0.30);
  EXPECT_EQ(elbow.center_of_mass_m, 0.15);
  EXPECT_EQ(elbow.inertia_kg_m2, 7.5e-4);
  EXPECT_EQ(elbow.tip_mass_kg, 0.0);
  EXPECT_EQ(elbow.stiffness_Nm_per_rad, 0.60);
  EXPECT_EQ(elbow.kappa_rad_per_bar, 7.91);
  EXPECT_EQ(elbow.omega0_straight_rad_per_s, 14.14);

  const ChainParameters arm3 = chain_preset("arm3");
  ASSERT_EQ(arm3.joints, 3);
  const double expected[3][9] = {{0.40, 0.25, 0.125, 2.08e-3, 0.30, 4.13, 5.0, 6.0, 0.31},
                                 {0.10, 0.30, 0.15, 7.5e-4, 0.15, 2.63, 6.0, 10.0, 0.31},
                                 {0.06, 0.20, 0.10, 2.0e-4, 0.0, 0.16, 7.91, 14.14, 0.31}};
  for (int i = 0; i < 3; ++i) {
    const ChainLink& l = arm3.links[static_cast<std::size_t>(i)];
    const double actual[9] = {l.mass_kg,           l.length_m,
                              l.center_of_mass_m,  l.inertia_kg_m2,
                              l.tip_mass_kg,       l.stiffness_Nm_per_rad,
                              l.kappa_rad_per_bar, l.omega0_straight_rad_per_s,
                              l.damping_ratio};
    for (int column = 0; column < 9; ++column)
      EXPECT_EQ(actual[column], expected[i][column]) << "joint " << i + 1 << " column " << column;
  }
  try {
    chain_preset("arm7");
    FAIL() << "an unknown preset must be refused";
  } catch (const InputError& e) {
    EXPECT_STREQ(e.what(), "unknown arm preset 'arm7' (known: arm2, arm3)");
  }
}

TEST(ArmChain, PresetsGiveTheSpecsDerivedNumbers) {
  // "Inertia about each joint with the arm straight: 0.0438 and 0.0030 kg m^2"; "Holding the
  // stretched-out arm against gravity takes about 0.12 bar (shoulder) and 0.03 bar (elbow)".
  const ArmChain arm2(chain_preset("arm2"));
  EXPECT_NEAR(arm2.straight_inertia_kg_m2()(0), 0.0438, 0.00005);
  EXPECT_NEAR(arm2.straight_inertia_kg_m2()(1), 0.0030, 0.00005);
  const JointVector hold2 = arm2.holding_pressure_bar(JointVector::Zero(2));
  EXPECT_NEAR(hold2(0), 0.12, 0.005);
  EXPECT_NEAR(hold2(1), 0.03, 0.005);
  // "0.115, 0.0263, 0.0008 kg m^2"; "Gravity at the shoulder, arm straight: about 2.8 N m (0.14 bar)".
  const ArmChain arm3(chain_preset("arm3"));
  EXPECT_NEAR(arm3.straight_inertia_kg_m2()(0), 0.115, 0.0005);
  EXPECT_NEAR(arm3.straight_inertia_kg_m2()(1), 0.0263, 0.00005);
  EXPECT_NEAR(arm3.straight_inertia_kg_m2()(2), 0.0008, 0.000005);
  EXPECT_NEAR(arm3.gravity_torque(JointVector::Zero(3))(0), 2.8, 0.05);
  EXPECT_NEAR(arm3.holding_pressure_bar(JointVector::Zero(3))(0), 0.14, 0.005);
  // The tables are consistent: K = w0^2 M_ii(0), and D_i = 2 delta w0 M_ii(0).
  for (const ArmChain* arm : {&arm2, &arm3}) {
    for (int i = 0; i < arm->joints(); ++i) {
      const ChainLink& l = arm->parameters().links[static_cast<std::size_t>(i)];
      const double w0 = l.omega0_straight_rad_per_s;
      EXPECT_NEAR(l.stiffness_Nm_per_rad / (w0 * w0 * arm->straight_inertia_kg_m2()(i)), 1.0, 0.01)
          << "joint " << i + 1;
      EXPECT_DOUBLE_EQ(arm->damping_Nms_per_rad()(i), 2.0 * 0.31 * w0 * arm->straight_inertia_kg_m2()(i));
    }
  }
}

TEST(ArmChain, TwoLinksMatchTheTextbookFormulas) {
  // Planar two-link arm with a point mass m_a1 at the end of link 1 (Spong, Robot Modeling and Control).
  const ChainParameters chain = chain_preset("arm2");
  const ArmChain arm(chain);
  const ChainLink& a = chain.links[0];
  const ChainLink& b = chain.links[1];
  std::mt19937 random(5);
  std::uniform_real_distribution<double> angle(-2.0, 2.0), rate(-5.0, 5.0);
  for (int trial = 0; trial < 20; ++trial) {
    const JointVector q = joints_vector({angle(random), angle(random)});
    const JointVector qd = joints_vector({rate(random), rate(random)});
    const double c2 = std::cos(q(1)), s2 = std::sin(q(1));
    const double h = b.mass_kg * a.length_m * b.center_of_mass_m;
    const double m22 = b.inertia_kg_m2 + b.mass_kg * b.center_of_mass_m * b.center_of_mass_m;
    const double m11 = a.inertia_kg_m2 + a.mass_kg * a.center_of_mass_m * a.center_of_mass_m +
                       a.tip_mass_kg * a.length_m * a.length_m + m22 + b.mass_kg * a.length_m * a.length_m +
                       2.0 * h * c2;
    const double m12 = m22 + h * c2;
    const JointMatrix M = arm.mass_matrix(q);
    EXPECT_NEAR(M(0, 0), m11, 1e-14);
    EXPECT_NEAR(M(0, 1), m12, 1e-14);
    EXPECT_NEAR(M(1, 0), m12, 1e-14);
    EXPECT_NEAR(M(1, 1), m22, 1e-14);
    const JointVector coriolis = arm.coriolis_torque(q, qd);
    EXPECT_NEAR(coriolis(0), -h * s2 * (2.0 * qd(0) * qd(1) + qd(1) * qd(1)), 1e-12);
    EXPECT_NEAR(coriolis(1), h * s2 * qd(0) * qd(0), 1e-12);
    const double c1 = std::cos(q(0)), c12 = std::cos(q(0) + q(1));
    const JointVector gravity = arm.gravity_torque(q);
    EXPECT_NEAR(gravity(0),
                kG * ((a.mass_kg * a.center_of_mass_m + (a.tip_mass_kg + b.mass_kg) * a.length_m) * c1 +
                      b.mass_kg * b.center_of_mass_m * c12),
                1e-12);
    EXPECT_NEAR(gravity(1), kG * b.mass_kg * b.center_of_mass_m * c12, 1e-12);
  }
}

TEST(ArmChain, GravityStiffnessIsTheDerivativeOfGravity) {
  const ArmChain arm(chain_preset("arm3"));
  const JointVector q = joints_vector({0.4, -0.9, 1.3});
  const JointMatrix analytic = arm.gravity_stiffness(q);
  constexpr double kStep = 1e-6;
  for (int m = 0; m < 3; ++m) {
    JointVector up = q, down = q;
    up(m) += kStep;
    down(m) -= kStep;
    const JointVector numeric = (arm.gravity_torque(up) - arm.gravity_torque(down)) / (2.0 * kStep);
    for (int j = 0; j < 3; ++j) EXPECT_NEAR(analytic(j, m), numeric(j), 1e-7) << j << ", " << m;
  }
}

TEST(ArmChain, EnergyIsConservedWithoutInputDampingAndCreep) {
  for (const char* preset : {"arm2", "arm3"}) {
    ArmChain arm(conservative(chain_preset(preset)));
    ArmChain::State start = arm.state();
    const int J = arm.joints();
    start.angle_rad = joints_vector({0.3, -0.5, 0.8}).head(J);
    start.velocity_rad_per_s = joints_vector({1.0, -2.0, 3.0}).head(J);
    arm.set_state(start);
    const double initial = arm.mechanical_energy_J(start);
    const JointVector no_input = JointVector::Zero(J);
    double kinetic_swing = 0.0, largest_drift = 0.0;
    for (int ms = 0; ms < 1000; ms += 5) {
      arm.advance(0.005, no_input);
      const ArmChain::State& s = arm.state();
      kinetic_swing =
          std::max(kinetic_swing, 0.5 * s.velocity_rad_per_s.dot(arm.mass_matrix(s.angle_rad) * s.velocity_rad_per_s));
      largest_drift = std::max(largest_drift, std::abs(arm.mechanical_energy_J(s) - initial));
    }
    EXPECT_GT(kinetic_swing, 0.05) << preset << ": the arm must actually swing";
    EXPECT_LT(largest_drift, 1e-9 * kinetic_swing + 1e-12) << preset;
    EXPECT_NEAR(arm.state().time_s, 1.0, 1e-9);
  }
}

TEST(ArmChain, DampingOnlyEverTakesEnergyOut) {
  ChainParameters chain = conservative(chain_preset("arm3"));
  for (ChainLink& l : chain.links) l.damping_ratio = 0.31;
  ArmChain arm(chain);
  ArmChain::State start = arm.state();
  start.velocity_rad_per_s = joints_vector({2.0, -3.0, 4.0});
  arm.set_state(start);
  double previous = arm.mechanical_energy_J(start);
  const double initial = previous;
  for (int ms = 0; ms < 1000; ms += 10) {
    arm.advance(0.01, JointVector::Zero(3));
    const double energy = arm.mechanical_energy_J(arm.state());
    EXPECT_LE(energy, previous + 1e-12) << "at " << ms << " ms";
    previous = energy;
  }
  EXPECT_GT(initial - previous, 0.1 * std::abs(initial));
}

TEST(ArmChain, GravityPullsAHorizontalLinkDown) {
  ChainParameters chain;
  chain.joints = 1;
  chain.links[0] = chain_preset("arm2").links[1];  // the elbow as a single link
  ArmChain arm(chain);
  const ChainLink& l = chain.links[0];
  const double joint_inertia = l.inertia_kg_m2 + l.mass_kg * l.center_of_mass_m * l.center_of_mass_m;
  const JointVector zero = JointVector::Zero(1);
  // At rest, stretched out, no pressure: only gravity, along -y, acts.
  EXPECT_NEAR(arm.acceleration(zero, zero, zero, zero)(0), -l.mass_kg * kG * l.center_of_mass_m / joint_inertia, 1e-12);
  arm.advance(0.05, zero);
  EXPECT_LT(arm.state().angle_rad(0), -1e-3);
  // Pointing straight up, gravity exerts no torque; a link hanging down beyond -90 deg is pulled back
  // (G enters the equation with a minus sign: G < 0 accelerates q upward).
  EXPECT_NEAR(arm.gravity_torque(joints_vector({std::numbers::pi / 2}))(0), 0.0, 1e-15);
  EXPECT_LT(arm.gravity_torque(joints_vector({-std::numbers::pi / 2 - 0.1}))(0), 0.0);
  EXPECT_GT(arm.gravity_torque(joints_vector({-std::numbers::pi / 2 + 0.1}))(0), 0.0);
  // Without gravity the stretched-out arm stays where it is.
  chain.gravity = false;
  ArmChain horizontal(chain);
  horizontal.advance(0.5, zero);
  EXPECT_EQ(horizontal.state().angle_rad(0), 0.0);

  // The whole arm2 released stretched out: the shoulder falls and the tip goes down.
  ArmChain arm2(conservative(chain_preset("arm2")));
  const double energy_before = arm2.mechanical_energy_J(arm2.state());
  arm2.advance(0.05, JointVector::Zero(2));
  EXPECT_LT(arm2.state().angle_rad(0), 0.0);
  const JointVector q = arm2.state().angle_rad;
  const double tip_height = 0.25 * std::sin(q(0)) + 0.30 * std::sin(q(0) + q(1));
  EXPECT_LT(tip_height, -1e-3);
  EXPECT_NEAR(arm2.mechanical_energy_J(arm2.state()), energy_before, 1e-9);  // fell, energy kept
}

TEST(ArmChain, OneJointWithoutGravityIsTheSingleJointArm) {
  // reference-system.md section 4: alpha_ddot = w0^2 (kappa dp - alpha - z) - 2 delta w0 alpha_dot,
  // z_dot = (c_z alpha - z) / tau_z, stiff spring and damper beyond +-95 deg.
  const PlantParameters plant;
  const ArmChain arm(single_joint_chain(plant));
  const double w0 = plant.omega0_rad_per_s;
  std::mt19937 random(9);
  std::uniform_real_distribution<double> angle(-1.9, 1.9), rate(-8.0, 8.0), creep(-0.3, 0.3), dp(-0.4, 0.4);
  for (int trial = 0; trial < 50; ++trial) {
    const double alpha = trial == 0 ? 100.0 * std::numbers::pi / 180.0 : angle(random);  // one beyond the stop
    const double alpha_dot = rate(random), z = creep(random), dp_bar = dp(random);
    double expected = w0 * w0 * (plant.kappa_rad_per_bar * dp_bar - alpha - z) - 2.0 * plant.damping * w0 * alpha_dot;
    const double beyond = std::abs(alpha) - plant.hard_stop_deg * std::numbers::pi / 180.0;
    if (beyond > 0.0) {
      expected -= (alpha > 0 ? 1.0 : -1.0) * plant.hard_stop_stiffness_per_s2 * beyond +
                  plant.hard_stop_damping_per_s * alpha_dot;
    }
    const double actual = arm.acceleration(joints_vector({alpha}), joints_vector({alpha_dot}), joints_vector({z}),
                                           joints_vector({dp_bar}))(0);
    EXPECT_NEAR(actual, expected, 1e-11 * (1.0 + std::abs(expected))) << "alpha " << alpha;
  }
}

TEST(ArmChain, HoldingPressureHoldsAPose) {
  ArmChain arm(chain_preset("arm3"));
  const JointVector pose = joints_vector({0.3, -0.4, 0.6});
  ArmChain::State s = arm.state();
  s.angle_rad = pose;
  for (int i = 0; i < 3; ++i) s.creep_rad(i) = 0.25 * pose(i);  // creep settled
  arm.set_state(s);
  arm.advance(2.0, arm.holding_pressure_bar(pose));
  EXPECT_LT((arm.state().angle_rad - pose).cwiseAbs().maxCoeff(), 1e-9);
  // Without the gravity share the arm sags.
  arm.set_state(s);
  JointVector no_gravity_share = arm.holding_pressure_bar(pose);
  no_gravity_share(0) -= arm.gravity_torque(pose)(0) / (4.13 * 5.0);
  arm.advance(2.0, no_gravity_share);
  EXPECT_LT(arm.state().angle_rad(0), pose(0) - 0.05);
}

TEST(ArmChain, HardStopsHoldEachJointNearItsRange) {
  ArmChain arm(chain_preset("arm2"));
  const JointVector full = joints_vector({0.39, 0.39});  // 0.39 bar * 7.91 rad/bar ~ 177 deg for the elbow
  double largest_elbow = 0.0;
  for (int ms = 0; ms < 2000; ms += 5) {
    arm.advance(0.005, full);
    largest_elbow = std::max(largest_elbow, arm.state().angle_rad(1));
  }
  const double stop = 95.0 * std::numbers::pi / 180.0;
  EXPECT_GT(largest_elbow, stop);
  EXPECT_LT(largest_elbow, stop + 8.0 * std::numbers::pi / 180.0);
  EXPECT_NEAR(arm.state().angle_rad(1), stop, 3.0 * std::numbers::pi / 180.0);
}

TEST(ArmChain, SameInputsGiveTheSameStatesAndAResumedRunContinuesExactly) {
  auto drive = [](ArmChain& arm, int from_ms, int to_ms) {
    for (int ms = from_ms; ms < to_ms; ms += 5) {
      const double t = ms * 1e-3;
      arm.advance(0.005, joints_vector({0.1 * std::sin(3.0 * t), 0.2 * std::cos(5.0 * t), -0.1 * std::sin(7.0 * t)}));
    }
  };
  ArmChain first(chain_preset("arm3")), second(chain_preset("arm3"));
  drive(first, 0, 300);
  const ArmChain::State middle = first.state();
  drive(first, 300, 600);
  drive(second, 0, 600);
  EXPECT_EQ(first.state().angle_rad, second.state().angle_rad);
  EXPECT_EQ(first.state().velocity_rad_per_s, second.state().velocity_rad_per_s);
  ArmChain resumed(chain_preset("arm3"));
  resumed.set_state(middle);
  drive(resumed, 300, 600);
  EXPECT_EQ(resumed.state().angle_rad, first.state().angle_rad);
  EXPECT_EQ(resumed.state().velocity_rad_per_s, first.state().velocity_rad_per_s);
  EXPECT_EQ(resumed.state().creep_rad, first.state().creep_rad);
  EXPECT_EQ(resumed.state().time_s, first.state().time_s);
  EXPECT_GT(first.state().angle_rad.cwiseAbs().maxCoeff(), 0.01);  // it moved
}

TEST(ArmChain, RefusesChainsItCannotSimulate) {
  ChainParameters none;
  EXPECT_THROW(ArmChain{none}, InputError);
  ChainParameters five = chain_preset("arm3");
  five.joints = 5;
  EXPECT_THROW(ArmChain{five}, InputError);
  ChainParameters negative = chain_preset("arm2");
  negative.links[1].mass_kg = -0.1;
  try {
    ArmChain{negative};
    FAIL();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("arm joint 2: mass_kg must be >= 0"), std::string::npos) << e.what();
  }
  ChainParameters massless = chain_preset("arm2");
  massless.links[1] = ChainLink{};
  massless.links[1].stiffness_Nm_per_rad = 1.0;
  massless.links[1].omega0_straight_rad_per_s = 10.0;
  EXPECT_THROW(ArmChain{massless}, InputError);  // nothing beyond the elbow to move: M is singular
  ChainParameters no_spring = chain_preset("arm2");
  no_spring.links[0].stiffness_Nm_per_rad = 0.0;
  EXPECT_THROW(ArmChain{no_spring}, InputError);

  ArmChain arm(chain_preset("arm2"));
  ArmChain::State wrong = arm.state();
  wrong.angle_rad = JointVector::Zero(3);
  EXPECT_THROW(arm.set_state(wrong), InputError);
}

}  // namespace
}  // namespace bellows
