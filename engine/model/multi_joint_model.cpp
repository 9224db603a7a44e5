#include "engine/model/multi_joint_model.hpp"

#include <string>

#include "engine/base/errors.hpp"

namespace bellows {

Eigen::MatrixXd MultiJointModel::lifted(int samples) const {
  const int J = joints();
  Eigen::MatrixXd P =
      Eigen::MatrixXd::Zero(static_cast<Eigen::Index>(samples) * J, static_cast<Eigen::Index>(samples) * J);
  Eigen::MatrixXd power_times_b = B;  // A^k B
  for (int lag = 0; lag < samples; ++lag) {
    const Eigen::MatrixXd markov = C * power_times_b;
    for (int column = 0; column + lag < samples; ++column) P.block((column + lag) * J, column * J, J, J) = markov;
    power_times_b = (A * power_times_b).eval();
  }
  return P;
}

MultiJointModel block_diagonal_model(std::span<const DiscreteArmModel> joints) {
  const int J = static_cast<int>(joints.size());
  if (J < 1 || J > kMaxJoints) {
    throw InputError("a multi-joint model needs 1 to " + std::to_string(kMaxJoints) + " joints, got " +
                     std::to_string(J));
  }
  MultiJointModel model;
  model.A.setZero(2 * J, 2 * J);
  model.B.setZero(2 * J, J);
  model.C.setZero(J, 2 * J);
  model.sample_time_s = joints[0].sample_time_s;
  for (int i = 0; i < J; ++i) {
    if (joints[i].sample_time_s != model.sample_time_s) {
      throw InputError("a multi-joint model's joints must share one sample time: joint " + std::to_string(i + 1) +
                       " differs from joint 1");
    }
    model.A.block<2, 2>(2 * i, 2 * i) = joints[i].A;
    model.B.block<2, 1>(2 * i, i) = joints[i].B;
    model.C.block<1, 2>(i, 2 * i) = joints[i].C;
  }
  return model;
}

Eigen::VectorXd stack_time_major(const Eigen::Ref<const Eigen::MatrixXd>& per_joint) {
  const Eigen::MatrixXd rows_first = per_joint.transpose();  // column t = sample t
  return Eigen::Map<const Eigen::VectorXd>(rows_first.data(), rows_first.size());
}

Eigen::MatrixXd unstack_time_major(const Eigen::Ref<const Eigen::VectorXd>& stacked, int joints) {
  const Eigen::Index samples = stacked.size() / joints;
  return Eigen::Map<const Eigen::MatrixXd>(stacked.data(), joints, samples).transpose();
}

}  // namespace bellows
