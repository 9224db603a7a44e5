// Learning transfer for an arm of J joints (issue 26; docs/learning-laws.md, "Transfer"): each
// joint's first correction is learned from that joint's part of the source sessions by the one-joint
// transfer (engine/config/learning_transfer), fitted, validated and falling back to zero on its own.
// The other joints' motion is part of what each joint's fit sees (the sources moved every joint as
// the target does), not modelled: a joint whose fit does not predict a gain gets no correction, and
// the result says why. With one joint this is the one-joint transfer, number for number. Both
// callers, `run --transfer-from` (app/transfer_sources) and the console's offer (ui/console_transfer),
// come through here.
#pragma once

#include <string>
#include <vector>

#include <Eigen/Dense>

#include "engine/config/learning_transfer.hpp"
#include "engine/trial/trial_record.hpp"

namespace bellows {

/// A source session of J joints: one one-joint TransferSource per joint (joint j's reference as a
/// one-joint trajectory, its correction, feedback and angle per trial).
struct JointTransferSource {
  std::string name;
  std::vector<TransferSource> joints;
  int trials() const { return joints.empty() ? 0 : static_cast<int>(joints.front().trials.size()); }
};

/// Joint `joint` of `trajectory` as a one-joint trajectory of the same name and sample time.
Trajectory joint_trajectory(const Trajectory& trajectory, int joint);

/// The trials `records` of a session on `trajectory` with `controller` as a source: those whose
/// columns hold the trajectory's N learning samples (N + 1 angles), in order.
JointTransferSource joint_transfer_source(std::string name, const Trajectory& trajectory,
                                          const ControllerParameters& controller,
                                          const std::vector<const TrialRecord*>& records);

struct JointTransferResult {
  std::vector<TransferResult> joints;  // one per joint of the target
  Eigen::MatrixXd correction_bar;      // N x J; zero in the joints that fell back

  bool transferred() const;  // at least one joint got a correction
  /// The first trial's predicted RMS over every joint and sample, with and without the corrections
  /// (one joint: its own figures).
  double predicted_rms_deg() const;
  double predicted_feedback_only_rms_deg() const;
};

/// Fits every joint's transfer from `sources` (each with the target's joint count, else InputError
/// naming it; LearningTransfer::setup's errors otherwise) and solves it for `target`.
JointTransferResult transfer_every_joint(const std::vector<JointTransferSource>& sources,
                                         const ControllerParameters& target_controller, double sample_time_s,
                                         const Trajectory& target, const TransferSettings& settings = {});

}  // namespace bellows
