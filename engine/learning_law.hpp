// A learning law: between trials, the next correction u_{j+1} from the last one u_j and the
// trial's normalized error e_j = (yD - y) / pi at samples 1..N. Laws are built once per model,
// weights and trial length (their expensive set-up happens there) and then updated per trial.
#pragma once

#include <Eigen/Dense>
#include <memory>
#include <string>

namespace bellows {

class LearningLaw {
 public:
  virtual ~LearningLaw() = default;
  /// u_next = law(u_j, e_j); all three have N entries. u_next may not alias the inputs.
  virtual void update(const Eigen::Ref<const Eigen::VectorXd>& u_j, const Eigen::Ref<const Eigen::VectorXd>& e_j,
                      Eigen::Ref<Eigen::VectorXd> u_next) = 0;
  /// The configuration name of the law, e.g. "noilc-dense".
  virtual std::string name() const = 0;
  virtual int samples() const = 0;
};

}  // namespace bellows
