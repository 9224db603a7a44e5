// The joints of the arm as the console names and shows them (issue 14): the selected joint's
// label, its set point in a tick, and which joint a guard fired on. With
// one joint nothing here adds to the screen (it looks as it did before joints were counted).
#pragma once

#include <string>
#include <vector>

#include <Eigen/Dense>

#include "engine/config/configuration.hpp"
#include "engine/rt/engine_messages.hpp"

namespace bellows::ui {

/// The spec's names of a chain's joints (shoulder, elbow, wrist for arm2 / arm3); "" for one joint
/// or a joint the presets do not name.
std::string joint_name(int joints, int joint);
/// "joint 2/2 elbow" (joint is 0-based); "" for one joint.
std::string joint_label(int joints, int joint);

/// Joint `joint`'s set point in a tick (joint 1's for a joint beyond kMaxJoints).
double tick_desired_rad(const TickRecord& tick, int joint);

/// Where a guard fired on a J-joint arm, in words ("joint 2 (elbow): angle 97.3 deg beyond its
/// limit of 95 deg"): the joint the engine named (`joint`, 0-based, the kFault event's fault_joint),
/// with its values from the tick that faulted; "" for one joint and for a fault that is no joint's
/// (supply, heartbeat, stop: `joint` < 0).
std::string fault_location(FaultCode code, int joint, const TickRecord& tick, const Configuration& config);

}  // namespace bellows::ui
