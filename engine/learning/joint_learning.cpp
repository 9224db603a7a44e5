#include "engine/learning/joint_learning.hpp"

#include "engine/base/errors.hpp"

namespace bellows {

void SingleJointLearning::update(const Eigen::Ref<const Eigen::MatrixXd>& u_j,
                                 const Eigen::Ref<const Eigen::MatrixXd>& e_j, Eigen::Ref<Eigen::MatrixXd> u_next) {
  if (u_j.cols() != 1 || e_j.cols() != 1 || u_next.cols() != 1) {
    throw InputError("a single-joint learning law was given " + std::to_string(u_j.cols()) + " joints");
  }
  law_.update(u_j.col(0), e_j.col(0), u_next.col(0));
}

void SingleJointLearning::set_input_context(const Eigen::Ref<const Eigen::MatrixXd>& feedback_bar,
                                            double input_limit_bar) {
  law_.set_input_context(feedback_bar.col(0), input_limit_bar);
}

}  // namespace bellows
