// The joint capacity of an arm and the fixed-capacity types sized by it. One joint is the default
// everywhere; the real-time tick handles up to kMaxJoints without allocating because every per-joint
// container has this capacity at compile time (issue 14, "dimensions first").
#pragma once

#include <Eigen/Core>

namespace bellows {

/// The largest joint count bellows handles: readings, commands, controllers, models, learning.
inline constexpr int kMaxJoints = 4;
/// A J-joint linear model has two states per joint (angle and velocity).
inline constexpr int kMaxJointStates = 2 * kMaxJoints;

/// A value per joint (size J at run time, storage for kMaxJoints: resizing within it never allocates).
using JointVector = Eigen::Matrix<double, Eigen::Dynamic, 1, 0, kMaxJoints, 1>;
/// A J x J matrix (mass matrix, coupled gains), the same fixed capacity.
using JointMatrix = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, 0, kMaxJoints, kMaxJoints>;

/// Whether `joints` is a joint count bellows can handle (1..kMaxJoints).
constexpr bool valid_joint_count(int joints) { return joints >= 1 && joints <= kMaxJoints; }

}  // namespace bellows
