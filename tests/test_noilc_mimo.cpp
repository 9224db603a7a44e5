// Norm-optimal ILC for J joints: the O(N) Riccati form (engine/learning/noilc_mimo) must give the dense lifted
// closed form's optimum (engine/learning/noilc_mimo_dense) to 1e-9 relative on random stable models and random
// data for J = 1..4, coupled and block-diagonal; with one joint both must be the single-joint laws.
#include <random>

#include <gtest/gtest.h>

#include "engine/model/arm_model.hpp"
#include "engine/base/errors.hpp"
#include "engine/learning/noilc_dense.hpp"
#include "engine/learning/noilc_mimo.hpp"
#include "engine/learning/noilc_mimo_dense.hpp"
#include "engine/learning/noilc_riccati.hpp"
#include "tests/allocation_counter.hpp"
#include "tests/multi_joint_random.hpp"

namespace bellows {
namespace {

using namespace mimo_test;

double relative_difference(const Eigen::MatrixXd& a, const Eigen::MatrixXd& reference) {
  return (a - reference).norm() / reference.norm();
}

struct TrialData {
  Eigen::MatrixXd u_j, e_j, target;
  TrialData(int samples, int joints, Random& random)
      : u_j(random.matrix(samples, joints, 0.2)),
        e_j(random.matrix(samples, joints, 0.1)),
        target(random.matrix(samples, joints, 0.2)) {}
};

/// Solves with both forms on three random trials and compares; also checks that the dense answer is
/// the optimum (its cost gradient vanishes), so the comparison is against the true minimizer.
void expect_riccati_equals_dense(const MultiJointModel& model, const MultiJointWeights& weights, int samples,
                                 double rho, Random& random) {
  const int J = model.joints();
  MultiJointNoilc riccati;
  ASSERT_EQ(riccati.setup(model, weights, samples, rho), MultiJointNoilcStatus::kOk);
  const MultiJointNoilcDense dense(model, weights, samples, rho);
  for (int trial = 0; trial < 3; ++trial) {
    const TrialData data(samples, J, random);
    Eigen::MatrixXd actual(samples, J);
    ASSERT_EQ(riccati.solve(data.u_j, data.e_j, data.target, actual), MultiJointNoilcStatus::kOk);
    const Eigen::MatrixXd expected = dense.solve(data.u_j, data.e_j, data.target);
    EXPECT_LT(relative_difference(actual, expected), 1e-9) << "J = " << J << ", N = " << samples << ", rho = " << rho;
    EXPECT_LT(dense.cost_gradient(data.u_j, data.e_j, data.target, actual).norm(), 1e-8 * (1.0 + data.e_j.norm()));
  }
  EXPECT_EQ(riccati.info().solves, 3);
  EXPECT_EQ(riccati.info().status, MultiJointNoilcStatus::kOk);
}

TEST(NoilcMimo, OneJointEqualsTheSingleJointLaws) {
  const DiscreteArmModel arm = discretize_arm_model(ModelParameters{}, kSampleTime_s);
  const MultiJointModel model = block_diagonal_model(std::span(&arm, 1));
  Random random(3);
  for (int samples : {2, 5, 200}) {
    const IlcParameters paper;
    MultiJointNoilc mimo;
    ASSERT_EQ(mimo.setup(model, MultiJointWeights::uniform(paper, 1), samples), MultiJointNoilcStatus::kOk);
    NormOptimalRiccati single(arm, paper, samples);
    NormOptimalDense single_dense(arm, paper, samples);
    const MultiJointNoilcDense mimo_dense(model, MultiJointWeights::uniform(paper, 1), samples);
    const TrialData data(samples, 1, random);
    Eigen::MatrixXd actual(samples, 1);
    ASSERT_EQ(mimo.update(data.u_j, data.e_j, actual), MultiJointNoilcStatus::kOk);
    Eigen::VectorXd expected(samples), expected_dense(samples);
    single.update(data.u_j.col(0), data.e_j.col(0), expected);
    single_dense.update(data.u_j.col(0), data.e_j.col(0), expected_dense);
    EXPECT_LT(relative_difference(actual.col(0), expected), 1e-12) << "N = " << samples;
    EXPECT_LT(relative_difference(mimo_dense.update(data.u_j, data.e_j).col(0), expected_dense), 1e-12)
        << "N = " << samples;
  }
}

TEST(NoilcMimo, CoupledModelEqualsDenseForOneToFourJoints) {
  Random random(17);
  for (int joints = 1; joints <= kMaxJoints; ++joints) {
    for (int samples : {2, 3, 60, 200}) {
      const MultiJointModel model = random_coupled_model(joints, random.between(0.5, 0.97), random);
      expect_riccati_equals_dense(model, random_full_weights(joints, random), samples, 0.0, random);
    }
  }
}

TEST(NoilcMimo, BlockDiagonalModelEqualsDenseForOneToFourJoints) {
  Random random(23);
  for (int joints = 1; joints <= kMaxJoints; ++joints) {
    const std::vector<DiscreteArmModel> arms = random_joint_models(joints, random);
    const MultiJointModel model = block_diagonal_model(arms);
    expect_riccati_equals_dense(model, random_full_weights(joints, random), 150, 0.0, random);
  }
}

TEST(NoilcMimo, ProximalTermEqualsDense) {  // the inner step a constrained variant will use
  Random random(29);
  for (int joints = 1; joints <= kMaxJoints; ++joints) {
    const MultiJointModel model = random_coupled_model(joints, 0.9, random);
    expect_riccati_equals_dense(model, random_full_weights(joints, random), 100, random.between(0.1, 3.0), random);
  }
}

TEST(NoilcMimo, SingularOutputWeightStillEqualsDense) {  // M only positive semidefinite: one joint not tracked
  Random random(31);
  const MultiJointModel model = random_coupled_model(3, 0.9, random);
  MultiJointWeights weights = random_full_weights(3, random);
  weights.m.setZero();
  weights.m(0, 0) = 1.0;
  weights.m(2, 2) = 2.0;
  expect_riccati_equals_dense(model, weights, 120, 0.0, random);
}

TEST(NoilcMimo, IndependentJointsWithPerJointWeightsAreTheSingleJointLawPerJoint) {
  Random random(37);
  const std::vector<DiscreteArmModel> arms = random_joint_models(3, random);
  std::vector<IlcParameters> per_joint(3);
  per_joint[0].m = 1.0, per_joint[0].s = 0.1, per_joint[0].w = 2e-5;
  per_joint[1].m = 3.0, per_joint[1].s = 0.05, per_joint[1].w = 1e-4;
  per_joint[2].m = 0.5, per_joint[2].s = 0.3, per_joint[2].w = 0.0;
  constexpr int kSamples = 180;
  MultiJointNoilc mimo;
  ASSERT_EQ(mimo.setup(block_diagonal_model(arms), MultiJointWeights::per_joint(per_joint), kSamples),
            MultiJointNoilcStatus::kOk);
  const TrialData data(kSamples, 3, random);
  Eigen::MatrixXd actual(kSamples, 3);
  ASSERT_EQ(mimo.update(data.u_j, data.e_j, actual), MultiJointNoilcStatus::kOk);
  for (int i = 0; i < 3; ++i) {
    NormOptimalRiccati single(arms[static_cast<std::size_t>(i)], per_joint[static_cast<std::size_t>(i)], kSamples);
    Eigen::VectorXd expected(kSamples);
    single.update(data.u_j.col(i), data.e_j.col(i), expected);
    EXPECT_LT(relative_difference(actual.col(i), expected), 1e-12) << "joint " << i + 1;
  }
}

TEST(NoilcMimo, CouplingCarriesOneJointsErrorIntoTheOthersCorrection) {
  // Error on joint 1 only: a coupled model corrects joint 2 too, independent joints leave it alone.
  Random random(41);
  constexpr int kSamples = 100;
  const std::vector<DiscreteArmModel> arms = random_joint_models(2, random);
  MultiJointModel coupled = block_diagonal_model(arms);
  coupled.B(1, 1) = 0.3 * coupled.B(1, 0);  // joint 2's pressure also accelerates joint 1
  const MultiJointWeights weights = MultiJointWeights::uniform(IlcParameters{}, 2);
  Eigen::MatrixXd u_j = Eigen::MatrixXd::Zero(kSamples, 2), e_j = Eigen::MatrixXd::Zero(kSamples, 2);
  e_j.col(0) = random.matrix(kSamples, 1, 0.1);
  Eigen::MatrixXd independent_next(kSamples, 2), coupled_next(kSamples, 2);
  MultiJointNoilc law;
  ASSERT_EQ(law.setup(block_diagonal_model(arms), weights, kSamples), MultiJointNoilcStatus::kOk);
  ASSERT_EQ(law.update(u_j, e_j, independent_next), MultiJointNoilcStatus::kOk);
  EXPECT_EQ(independent_next.col(1).norm(), 0.0);
  ASSERT_EQ(law.setup(coupled, weights, kSamples), MultiJointNoilcStatus::kOk);
  ASSERT_EQ(law.update(u_j, e_j, coupled_next), MultiJointNoilcStatus::kOk);
  EXPECT_GT(coupled_next.col(1).norm(), 0.05 * coupled_next.col(0).norm());
}

TEST(NoilcMimo, SetupReportsEveryBadInput) {
  Random random(43);
  const MultiJointModel good = random_coupled_model(2, 0.9, random);
  const MultiJointWeights weights = MultiJointWeights::uniform(IlcParameters{}, 2);
  MultiJointNoilc law;
  EXPECT_EQ(law.info().status, MultiJointNoilcStatus::kNotSetUp);

  MultiJointModel empty;
  EXPECT_EQ(law.setup(empty, weights, 100), MultiJointNoilcStatus::kBadJointCount);
  EXPECT_EQ(law.setup(good, weights, 1), MultiJointNoilcStatus::kTooFewSamples);
  MultiJointModel nan_model = good;
  nan_model.A(1, 2) = std::nan("");
  EXPECT_EQ(law.setup(nan_model, weights, 100), MultiJointNoilcStatus::kBadModel);
  MultiJointModel wrong_shape = good;
  wrong_shape.B.resize(4, 1);
  EXPECT_EQ(law.setup(wrong_shape, weights, 100), MultiJointNoilcStatus::kBadModel);
  MultiJointModel no_time = good;
  no_time.sample_time_s = 0.0;
  EXPECT_EQ(law.setup(no_time, weights, 100), MultiJointNoilcStatus::kBadModel);

  MultiJointWeights asymmetric = weights;
  asymmetric.m(0, 1) = 0.5;
  EXPECT_EQ(law.setup(good, asymmetric, 100), MultiJointNoilcStatus::kBadWeights);
  MultiJointWeights indefinite = weights;
  indefinite.s(1, 1) = -0.1;
  EXPECT_EQ(law.setup(good, indefinite, 100), MultiJointNoilcStatus::kBadWeights);
  MultiJointWeights coupled_indefinite = weights;  // positive diagonal, eigenvalues -1 and 3
  coupled_indefinite.m << 1.0, 2.0, 2.0, 1.0;
  EXPECT_EQ(law.setup(good, coupled_indefinite, 100), MultiJointNoilcStatus::kBadWeights);
  MultiJointWeights coupled_singular = weights;  // eigenvalues 0 and 2: semidefinite, allowed
  coupled_singular.m << 1.0, 1.0, 1.0, 1.0;
  EXPECT_EQ(law.setup(good, coupled_singular, 100), MultiJointNoilcStatus::kOk);
  MultiJointWeights three_joints = MultiJointWeights::uniform(IlcParameters{}, 3);
  EXPECT_EQ(law.setup(good, three_joints, 100), MultiJointNoilcStatus::kBadWeights);
  EXPECT_EQ(law.setup(good, weights, 100, -1.0), MultiJointNoilcStatus::kBadWeights);
  MultiJointWeights nothing = weights;  // no weight on anything: every correction is optimal
  nothing.m.setZero();
  nothing.s.setZero();
  nothing.w.setZero();
  EXPECT_EQ(law.setup(good, nothing, 100), MultiJointNoilcStatus::kNotPositiveDefinite);
  EXPECT_EQ(law.info().status, MultiJointNoilcStatus::kNotPositiveDefinite);
  EXPECT_STREQ(to_string(MultiJointNoilcStatus::kNotPositiveDefinite),
               "the weights do not give a positive definite cost");

  Eigen::MatrixXd u(100, 2), out(100, 2);
  u.setZero();
  EXPECT_EQ(law.update(u, u, out), MultiJointNoilcStatus::kNotSetUp);  // a failed setup leaves it unusable
  EXPECT_THROW(block_diagonal_model(std::span<const DiscreteArmModel>()), InputError);
}

TEST(NoilcMimo, SolveRefusesBadDataAndLeavesTheOutputAlone) {
  Random random(47);
  constexpr int kSamples = 80;
  MultiJointNoilc law;
  ASSERT_EQ(
      law.setup(random_coupled_model(3, 0.9, random), MultiJointWeights::uniform(IlcParameters{}, 3), kSamples, 0.5),
      MultiJointNoilcStatus::kOk);
  const TrialData data(kSamples, 3, random);
  Eigen::MatrixXd out = Eigen::MatrixXd::Constant(kSamples, 3, 7.0);
  const Eigen::MatrixXd untouched = out;
  Eigen::MatrixXd short_trial = data.u_j.topRows(kSamples - 1);
  Eigen::MatrixXd two_joints = data.u_j.leftCols(2);
  EXPECT_EQ(law.solve(short_trial, data.e_j, data.target, out), MultiJointNoilcStatus::kShapeMismatch);
  EXPECT_EQ(law.solve(data.u_j, two_joints, data.target, out), MultiJointNoilcStatus::kShapeMismatch);
  EXPECT_EQ(law.solve(data.u_j, data.e_j, short_trial, out),
            MultiJointNoilcStatus::kShapeMismatch);  // rho > 0 reads it
  Eigen::MatrixXd with_nan = data.e_j;
  with_nan(40, 2) = std::nan("");
  EXPECT_EQ(law.solve(data.u_j, with_nan, data.target, out), MultiJointNoilcStatus::kNonFiniteData);
  Eigen::MatrixXd with_inf = data.target;
  with_inf(3, 0) = std::numeric_limits<double>::infinity();
  EXPECT_EQ(law.solve(data.u_j, data.e_j, with_inf, out), MultiJointNoilcStatus::kNonFiniteData);
  EXPECT_EQ(law.info().status, MultiJointNoilcStatus::kNonFiniteData);
  EXPECT_EQ(out, untouched);
  EXPECT_EQ(law.info().solves, 0);
  EXPECT_EQ(law.solve(data.u_j, data.e_j, data.target, out), MultiJointNoilcStatus::kOk);
  EXPECT_NE(out, untouched);
  EXPECT_GT(law.info().memory_bytes, static_cast<std::size_t>(kSamples) * 9 * 3 * sizeof(double));
}

TEST(NoilcMimo, SolveAllocatesNothing) {
  Random random(53);
  constexpr int kSamples = 120;
  for (int joints = 1; joints <= kMaxJoints; ++joints) {
    MultiJointNoilc law;
    ASSERT_EQ(law.setup(random_coupled_model(joints, 0.9, random), random_full_weights(joints, random), kSamples, 0.2),
              MultiJointNoilcStatus::kOk);
    const TrialData data(kSamples, joints, random);
    Eigen::MatrixXd out(kSamples, joints);
    EXPECT_EQ(testing_allocations::probe_allocations(), 1);  // the instrument works
    long allocations = 0;
    MultiJointNoilcStatus solved, updated;
    {
      testing_allocations::Counter counter;
      solved = law.solve(data.u_j, data.e_j, data.target, out);
      updated = law.update(data.u_j, data.e_j, out);
      allocations = counter.allocations();
    }
    EXPECT_EQ(solved, MultiJointNoilcStatus::kOk);
    EXPECT_EQ(updated, MultiJointNoilcStatus::kOk);
    EXPECT_EQ(allocations, 0) << "J = " << joints;
  }
}

}  // namespace
}  // namespace bellows
