// What learning predicts and observes for an arm of several joints, in words: the convergence
// prediction (engine/config/joint_convergence) and the wind-up monitor (engine/learning/
// learning_monitor) per joint. One wording for `bellows run`'s progress lines and the console's
// tuning screen and log (docs/learning-laws.md, "Several joints").
#pragma once

#include <string>
#include <vector>

#include "engine/config/joint_convergence.hpp"
#include "engine/learning/learning_monitor.hpp"

namespace bellows::ui {

/// The law that keeps the set points inside the limits: the remedy wind-up lines name.
inline constexpr const char* kWindupRemedyLaw = "noilc-constrained";

/// The arm's prediction, then one line per joint, e.g.
///   "convergence prediction (noilc, 2 joints learned together, coupled closed loop): contraction per
///    trial 0.990 (nominal model); 0.995 at worst for a model off by up to 30 %"
///   "  joint 1/2 shoulder: keeps at most 0.962 of the arm's correction error per trial; 12 % of the
///    slowest direction"
/// A warning follows the first line ("warning: ..."); an unavailable prediction says why.
std::vector<std::string> joint_prediction_lines(const JointConvergencePrediction& prediction, const std::string& law);

/// The console's tuning-screen line: the arm's contraction and each joint's, in one sentence.
std::string joint_prediction_summary(const JointConvergencePrediction& prediction, const std::string& law);

/// "wind-up of joint 2/2 elbow since iteration 5: the correction keeps growing where the set points
/// saturate (largest clamped excess 0.031 bar); law noilc-constrained avoids it" (`joint` 0-based of
/// `joints`; with one joint, no joint named).
std::string windup_warning(const WindupSummary& windup, int joints, int joint);

/// The wind-up monitor per joint after `trials` trials, one line each: the warning for a joint that
/// wound up, else "wind-up monitor, joint 1/2 shoulder: none in 30 trials (largest clamped excess
/// 0.0000 bar, 0 trials with growth into the clamp)".
std::vector<std::string> windup_monitor_lines(const WindupSummary& windup, int trials);

}  // namespace bellows::ui
