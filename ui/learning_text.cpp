#include "ui/learning_text.hpp"

#include "ui/canvas.hpp"
#include "ui/joint_view.hpp"

namespace bellows::ui {
namespace {

std::string unavailable_line(const JointConvergencePrediction& p, const std::string& law) {
  return "no convergence prediction for law " + law +
         (p.unavailable_reason.empty() ? std::string() : " (" + p.unavailable_reason + ")");
}

}  // namespace

std::vector<std::string> joint_prediction_lines(const JointConvergencePrediction& p, const std::string& law) {
  const int joints = static_cast<int>(p.joints.size());
  if (!p.arm.available) return {unavailable_line(p, law)};
  std::vector<std::string> lines = {
      format("convergence prediction (%s, %d joints %s, coupled closed loop): contraction per trial "
             "%.3f (nominal model); %.3f at worst for a model off by up to %.0f %%",
             law.c_str(), joints, p.learned_together ? "learned together" : "each learned on its own",
             p.arm.nominal.contraction, p.arm.worst.contraction, 100.0 * p.arm.model_error)};
  if (!p.arm.warning.empty()) lines.push_back("warning: " + p.arm.warning);
  for (int j = 0; j < joints; ++j) {
    const JointConvergence& joint = p.joints[static_cast<std::size_t>(j)];
    std::string line = format(
        "  %s: keeps at most %.3f of the arm's correction error per trial; %.0f %% of the "
        "slowest direction",
        joint_label(joints, j).c_str(), joint.contraction, 100.0 * joint.slowest_direction_share);
    if (joint.own.available) {
      line +=
          format("; on its own model %.3f, %.3f at worst", joint.own.nominal.contraction, joint.own.worst.contraction);
    }
    lines.push_back(line);
  }
  return lines;
}

std::string joint_prediction_summary(const JointConvergencePrediction& p, const std::string& law) {
  if (!p.arm.available) return unavailable_line(p, law);
  if (!p.arm.warning.empty()) return p.arm.warning;
  std::string per_joint;
  for (std::size_t j = 0; j < p.joints.size(); ++j) {
    const std::string name = joint_name(static_cast<int>(p.joints.size()), static_cast<int>(j));
    per_joint += format("%s%s %.3f", j == 0 ? "" : ", ",
                        name.empty() ? format("joint %zu", j + 1).c_str() : name.c_str(), p.joints[j].contraction);
  }
  return format(
      "predicted contraction per trial %.3f for the arm (coupled closed loop, nominal model); %.3f at worst "
      "for a model off by up to %.0f %%; per joint %s",
      p.arm.nominal.contraction, p.arm.worst.contraction, 100.0 * p.arm.model_error, per_joint.c_str());
}

std::string windup_warning(const WindupSummary& w, int joints, int joint) {
  const std::string whose = joints > 1 ? " of " + joint_label(joints, joint) : std::string();
  return format(
      "wind-up%s since iteration %d: the correction keeps growing where the set points saturate "
      "(largest clamped excess %.3f bar); law %s avoids it",
      whose.c_str(), w.first_iteration.value_or(0), w.max_clamped_excess_bar, kWindupRemedyLaw);
}

std::vector<std::string> windup_monitor_lines(const WindupSummary& w, int trials) {
  const int joints = static_cast<int>(w.joints.size());
  std::vector<std::string> lines;
  for (int j = 0; j < joints; ++j) {
    const WindupSummary& joint = w.joints[static_cast<std::size_t>(j)];
    if (joint.detected) {
      lines.push_back("warning: " + windup_warning(joint, joints, j));
      continue;
    }
    lines.push_back(
        format("wind-up monitor, %s: none in %d trials (largest clamped excess %.4f bar, %d trials with "
               "growth into the clamp)",
               joint_label(joints, j).c_str(), trials, joint.max_clamped_excess_bar, joint.iterations_with_windup));
  }
  return lines;
}

}  // namespace bellows::ui
