#include "ui/experiment.hpp"

#include <algorithm>
#include <limits>
#include <string>
#include <vector>

namespace bellows::ui {

Experiment Experiment::start(std::shared_ptr<const Trajectory> trajectory) {
  Experiment e;
  e.trajectory = std::move(trajectory);
  e.next_correction_bar = Eigen::MatrixXd::Zero(e.samples(), e.joints());
  return e;
}

std::string Experiment::unsaved_sentence() const {
  std::vector<std::string> parts;
  const int iterations = static_cast<int>(trials.size()) - saved_trials;
  const int black_boxes = static_cast<int>(faults.size()) - saved_faults;
  const int first = std::max(saved_trials, 0), last = static_cast<int>(trials.size()) - 1;
  // Which trials are not on disk, by number: the operator checks them against the history.
  if (iterations == 1) parts.push_back("iteration " + std::to_string(last));
  if (iterations > 1)
    parts.push_back(std::to_string(iterations) + " iterations (" + std::to_string(first) + "-" + std::to_string(last) +
                    ")");
  if (black_boxes > 0) {
    parts.push_back(std::to_string(black_boxes) + (black_boxes == 1 ? " fault's black box" : " faults' black boxes"));
  }
  if (settings_changed) parts.push_back("changed settings");
  const bool next = next_unsaved && !trials.empty() && iterations <= 0;
  if (next) parts.push_back("the correction learned from iteration " + std::to_string(last));
  if (parts.empty()) return {};
  std::string sentence = parts[0];
  for (std::size_t i = 1; i < parts.size(); ++i) sentence += (i + 1 == parts.size() ? " and " : ", ") + parts[i];
  const bool one = parts.size() == 1 && (iterations == 1 || black_boxes == 1 || next);
  return sentence + (one ? " is not saved." : " are not saved.");
}

void Experiment::add_trial(Trial trial) {
  trial.iteration = next_iteration();
  trials.push_back(std::move(trial));
  next_tried = true;
}

void Experiment::set_next(Eigen::MatrixXd correction_bar, std::string origin, LearnedWith learned_with) {
  next_correction_bar = std::move(correction_bar);
  next_origin = std::move(origin);
  next_learned_with = std::move(learned_with);
  next_tried = false;
  next_unsaved = true;
  ++next_revision;
}

void Experiment::release_saved_history() {
  const int keep_from = std::min(saved_trials, static_cast<int>(trials.size()) - kTrialsKeptInMemory);
  for (int i = 0; i < keep_from; ++i) {
    Trial& t = trials[static_cast<std::size_t>(i)];
    if (!t.in_memory()) continue;
    t.record = TrialRecord{};
    t.correction_bar = Eigen::MatrixXd();
  }
  for (int i = 0; i < std::min(saved_faults, static_cast<int>(faults.size())); ++i) {
    std::vector<TickRecord>().swap(faults[static_cast<std::size_t>(i)].ticks);
  }
}

std::vector<double> Experiment::rms_history_deg() const {
  std::vector<double> rms;
  rms.reserve(trials.size());
  for (const Trial& t : trials) rms.push_back(t.summary.rms_deg);
  return rms;
}

std::vector<double> Experiment::joint_rms_history_deg(int joint) const {
  std::vector<double> rms;
  rms.reserve(trials.size());
  for (const Trial& t : trials) {
    const bool known = joint >= 0 && joint < t.summary.joint_rms_deg.size();
    rms.push_back(known ? t.summary.joint_rms_deg(joint)
                        : (joint == 0 ? t.summary.rms_deg : std::numeric_limits<double>::quiet_NaN()));
  }
  return rms;
}

double Experiment::best_rms_deg() const {
  double best = -1.0;
  for (const Trial& t : trials) {
    if (best < 0.0 || t.summary.rms_deg < best) best = t.summary.rms_deg;
  }
  return best;
}

bool Experiment::rms_rising(int count) const {
  const int n = static_cast<int>(trials.size());
  if (count <= 0 || n < count + 1) return false;
  for (int i = n - count; i < n; ++i) {
    if (!(trials[static_cast<std::size_t>(i)].summary.rms_deg >
          trials[static_cast<std::size_t>(i - 1)].summary.rms_deg)) {
      return false;
    }
  }
  return true;
}

}  // namespace bellows::ui
