#include "engine/config/joint_transfer.hpp"

#include <algorithm>
#include <cmath>

#include "engine/base/errors.hpp"

namespace bellows {
namespace {

/// RMS over every joint of per-joint RMS values of equal sample counts; one joint: its own.
double joints_rms(const std::vector<TransferResult>& joints, double TransferResult::*rms_deg) {
  if (joints.size() == 1) return joints.front().*rms_deg;
  double squares = 0.0;
  for (const TransferResult& joint : joints) squares += (joint.*rms_deg) * (joint.*rms_deg);
  return joints.empty() ? 0.0 : std::sqrt(squares / static_cast<double>(joints.size()));
}

}  // namespace

Trajectory joint_trajectory(const Trajectory& trajectory, int joint) {
  Trajectory one;
  one.name = trajectory.name;
  one.sample_time_s = trajectory.sample_time_s;
  one.angles_rad = {trajectory.joint(joint)};
  return one;
}

JointTransferSource joint_transfer_source(std::string name, const Trajectory& trajectory,
                                          const ControllerParameters& controller,
                                          const std::vector<const TrialRecord*>& records) {
  JointTransferSource source;
  source.name = std::move(name);
  const Eigen::Index n = trajectory.learning_samples();
  for (int j = 0; j < trajectory.joints(); ++j) {
    TransferSource joint;
    joint.name = source.name;
    joint.trajectory = joint_trajectory(trajectory, j);
    joint.controller = controller;
    source.joints.push_back(std::move(joint));
  }
  for (const TrialRecord* record : records) {
    if (record->joint_count() != trajectory.joints()) continue;
    bool whole = true;
    for (int j = 0; j < trajectory.joints(); ++j) {
      const TrialSamples& s = record->joint_samples(j);
      whole = whole && s.u_ilc_bar.size() >= n && s.u_pid_bar.size() >= n && s.angle_rad.size() >= n + 1;
    }
    if (!whole) continue;
    for (int j = 0; j < trajectory.joints(); ++j) {
      const TrialSamples& s = record->joint_samples(j);
      source.joints[static_cast<std::size_t>(j)].trials.push_back(
          {s.u_ilc_bar.head(n), s.u_pid_bar.head(n), s.angle_rad.head(n + 1)});
    }
  }
  return source;
}

bool JointTransferResult::transferred() const {
  for (const TransferResult& joint : joints) {
    if (joint.status == TransferStatus::kTransferred) return true;
  }
  return false;
}

double JointTransferResult::predicted_rms_deg() const { return joints_rms(joints, &TransferResult::predicted_rms_deg); }

double JointTransferResult::predicted_feedback_only_rms_deg() const {
  return joints_rms(joints, &TransferResult::predicted_feedback_only_rms_deg);
}

JointTransferResult transfer_every_joint(const std::vector<JointTransferSource>& sources,
                                         const ControllerParameters& target_controller, double sample_time_s,
                                         const Trajectory& target, const TransferSettings& settings) {
  const int joints = target.joints();
  for (const JointTransferSource& source : sources) {
    if (static_cast<int>(source.joints.size()) != joints) {
      throw InputError("session '" + source.name + "' has " + std::to_string(source.joints.size()) +
                       " joints, trajectory '" + target.name + "' " + std::to_string(joints) +
                       ": it cannot teach this run");
    }
  }
  JointTransferResult result;
  result.correction_bar = Eigen::MatrixXd::Zero(std::max(0, target.learning_samples()), joints);
  for (int j = 0; j < joints; ++j) {
    std::vector<TransferSource> joint_sources;
    joint_sources.reserve(sources.size());
    for (const JointTransferSource& source : sources)
      joint_sources.push_back(source.joints[static_cast<std::size_t>(j)]);
    LearningTransfer transfer(settings);
    transfer.setup(std::move(joint_sources), target_controller, sample_time_s);
    result.joints.push_back(transfer.solve(joint_trajectory(target, j)));
    if (result.joints.back().correction_bar.size() == result.correction_bar.rows())
      result.correction_bar.col(j) = result.joints.back().correction_bar;
  }
  return result;
}

}  // namespace bellows
