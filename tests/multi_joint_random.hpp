// Random models, weights and data for the J-joint learning-law tests.
#pragma once

#include <cmath>
#include <random>
#include <vector>

#include <Eigen/Dense>

#include "engine/model/arm_model.hpp"
#include "engine/learning/noilc_mimo.hpp"

namespace bellows::mimo_test {

constexpr double kSampleTime_s = 0.02;

class Random {
 public:
  explicit Random(unsigned seed) : engine_(seed) {}
  double normal() { return normal_(engine_); }
  /// Log-uniform in [low, high].
  double between(double low, double high) { return low * std::pow(high / low, uniform_(engine_)); }
  Eigen::MatrixXd matrix(Eigen::Index rows, Eigen::Index cols, double scale) {
    Eigen::MatrixXd m(rows, cols);
    for (Eigen::Index i = 0; i < m.size(); ++i) m.data()[i] = scale * normal();
    return m;
  }
  /// A random symmetric positive definite J x J matrix of size ~`scale`, condition number <= ~20.
  JointMatrix spd(int joints, double scale) {
    const Eigen::MatrixXd R = matrix(joints, joints, 1.0);
    Eigen::MatrixXd S = R * R.transpose() / joints;
    S.diagonal().array() += 0.1 * (1.0 + S.diagonal().maxCoeff());
    return scale * S / S.diagonal().mean();
  }

 private:
  std::mt19937 engine_;
  std::normal_distribution<double> normal_{0.0, 1.0};
  std::uniform_real_distribution<double> uniform_{0.0, 1.0};
};

/// A coupled model: random A scaled to spectral radius `radius`, random B and C.
inline MultiJointModel random_coupled_model(int joints, double radius, Random& random) {
  MultiJointModel model;
  const Eigen::MatrixXd A = random.matrix(2 * joints, 2 * joints, 1.0);
  const double spectral_radius = Eigen::EigenSolver<Eigen::MatrixXd>(A, false).eigenvalues().cwiseAbs().maxCoeff();
  model.A = A * (radius / spectral_radius);
  model.B = random.matrix(2 * joints, joints, 0.5);
  model.C = random.matrix(joints, 2 * joints, 1.0);
  model.sample_time_s = kSampleTime_s;
  return model;
}

/// J arms of the spec's form with kappa, omega0 and delta drawn around the paper's values.
inline std::vector<DiscreteArmModel> random_joint_models(int joints, Random& random) {
  std::vector<DiscreteArmModel> models;
  for (int i = 0; i < joints; ++i) {
    ModelParameters p;
    p.kappa_rad_per_bar = random.between(3.0, 12.0);
    p.omega0_rad_per_s = random.between(5.0, 25.0);
    p.damping = random.between(0.1, 0.9);
    models.push_back(discretize_arm_model(p, kSampleTime_s));
  }
  return models;
}

inline MultiJointWeights random_full_weights(int joints, Random& random) {
  MultiJointWeights w;
  w.m = random.spd(joints, random.between(0.2, 5.0));
  w.s = random.spd(joints, random.between(0.01, 1.0));
  w.w = random.spd(joints, random.between(1e-6, 1e-4));
  return w;
}

}  // namespace bellows::mimo_test
