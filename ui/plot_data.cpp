#include "ui/plot_data.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

#include "engine/base/units.hpp"

namespace bellows::ui {
namespace {

std::vector<double> to_vector(const Eigen::Ref<const Eigen::VectorXd>& v, double scale, Eigen::Index count) {
  std::vector<double> out(static_cast<std::size_t>(count));
  for (Eigen::Index i = 0; i < count; ++i) out[static_cast<std::size_t>(i)] = v(i) * scale;
  return out;
}
}  // namespace

TrialSeries trial_series(const TrialRecord& record, int joint) {
  const TrialSamples& s = record.joint_samples(joint > 0 && joint < record.joint_count() ? joint : 0);
  const Eigen::Index n = record.sample_time_s.size();
  return {to_vector(record.sample_time_s, 1.0, n), to_vector(s.angle_rad, kDegPerRad, n),
          to_vector(s.setpoint_rad, kDegPerRad, n)};
}

RmsSeries rms_series(const Experiment& experiment, int joint) {
  RmsSeries out;
  out.rms_deg = joint < 0 ? experiment.rms_history_deg() : experiment.joint_rms_history_deg(joint);
  for (const Trial& t : experiment.trials) {
    out.iteration.push_back(t.iteration);
    out.max_error_deg.push_back(t.summary.max_abs_error_deg);
  }
  return out;
}

std::vector<double> error_series_deg(const TrialRecord& record, int joint) {
  const TrialSamples& s = record.joint_samples(joint > 0 && joint < record.joint_count() ? joint : 0);
  return to_vector(s.error_rad, kDegPerRad, s.error_rad.size());
}

std::vector<int> error_peaks(const TrialRecord& record, int joint) {
  const std::vector<double> e = error_series_deg(record, joint);
  const int n = std::min(record.learning_samples, static_cast<int>(e.size()) - 1);
  const auto at = [&](int k) { return std::abs(e[static_cast<std::size_t>(k)]); };
  std::vector<int> peaks;
  for (int k = 1; k <= n; ++k) {
    // A local maximum; on a plateau its first sample only.
    const bool rises_to = k == 1 || at(k) > at(k - 1);
    const bool falls_after = k == n || at(k) >= at(k + 1);
    if (rises_to && falls_after && std::isfinite(at(k))) peaks.push_back(k);
  }
  std::stable_sort(peaks.begin(), peaks.end(), [&](int a, int b) { return at(a) > at(b); });
  return peaks;
}

TrialDifference trial_difference(const Experiment& e, int trial, int other, int joint) {
  TrialDifference d;
  const int trials = static_cast<int>(e.trials.size());
  if (trial < 0 || trial >= trials || other < 0 || other >= trials || trial == other) {
    d.why = "choose another iteration with m";
    return d;
  }
  const Trial& a = e.trials[static_cast<std::size_t>(trial)];
  const Trial& b = e.trials[static_cast<std::size_t>(other)];
  d.iteration = a.iteration;
  d.other_iteration = b.iteration;
  if (!a.in_memory() || !b.in_memory()) {
    d.why = format("iteration %d is on disk only", !a.in_memory() ? a.iteration : b.iteration);
    return d;
  }
  if (joint >= a.record.joint_count() || joint >= b.record.joint_count() ||
      a.record.learning_samples != b.record.learning_samples) {
    d.why = "the two records differ in shape";
    return d;
  }
  const TrialSamples& sa = a.record.joint_samples(joint);
  const TrialSamples& sb = b.record.joint_samples(joint);
  const int n = a.record.learning_samples;
  d.du_bar.resize(static_cast<std::size_t>(n));
  d.de_deg.resize(static_cast<std::size_t>(n) + 1);
  double du2 = 0.0, de2 = 0.0;
  for (int k = 0; k <= n; ++k) {
    const double de = (sa.error_rad(k) - sb.error_rad(k)) * kDegPerRad;
    d.de_deg[static_cast<std::size_t>(k)] = de;
    if (k >= 1) de2 += de * de;
    if (k < n) {
      const double du = sa.u_ilc_bar(k) - sb.u_ilc_bar(k);
      d.du_bar[static_cast<std::size_t>(k)] = du;
      du2 += du * du;
    }
  }
  d.rms_du_bar = n > 0 ? std::sqrt(du2 / n) : 0.0;
  d.rms_de_deg = n > 0 ? std::sqrt(de2 / n) : 0.0;
  d.available = true;
  return d;
}

CorrectionOverlay correction_overlay(const Experiment& e, int primary, int chosen, int joint) {
  CorrectionOverlay out;
  const int n = e.samples();
  if (n <= 0 || !e.trajectory) return out;
  const int trials = static_cast<int>(e.trials.size());
  out.time_s.resize(static_cast<std::size_t>(n));
  for (int k = 0; k < n; ++k) out.time_s[static_cast<std::size_t>(k)] = k * e.trajectory->sample_time_s;
  const auto matrix_of = [&](int i) -> const Eigen::MatrixXd& {
    return i < 0 ? e.next_correction_bar : e.trials[static_cast<std::size_t>(i)].correction_bar;
  };
  // Released corrections (on disk only) and a joint a correction does not have show nothing.
  const auto in_memory = [&](int i) { return matrix_of(i).rows() >= n && matrix_of(i).cols() > joint; };
  const auto correction_of = [&](int i) { return matrix_of(i).col(joint); };
  const auto label_of = [&](int i) { return i < 0 ? std::string("next") : "it " + std::to_string(i); };
  const int previous = primary < 0 ? trials - 1 : primary - 1;
  if (previous >= 0 && in_memory(previous))
    out.series.push_back({label_of(previous), Role::kSeries2, '.', to_vector(correction_of(previous), 1.0, n)});
  if (chosen >= 0 && chosen < trials && chosen != primary && chosen != previous && in_memory(chosen)) {
    out.series.push_back({label_of(chosen), Role::kSeries3, 'o', to_vector(correction_of(chosen), 1.0, n)});
  }
  if (primary < trials && in_memory(primary))
    out.series.push_back({label_of(primary), Role::kSeries1, '*', to_vector(correction_of(primary), 1.0, n)});
  // A transferred start stays in view beside what was learned from it.
  if (trials > 0 && in_memory(0) && e.trials.front().origin.rfind("transferred", 0) == 0 && primary != 0 &&
      previous != 0 && chosen != 0) {
    out.series.insert(out.series.begin(), {"transferred", Role::kSeries3, '+', to_vector(correction_of(0), 1.0, n)});
  }
  return out;
}

CorrectionOverlay correction_overlay(const ConsoleState& s) {
  const Experiment& e = s.experiment;
  const bool untouched = e.trials.empty() && (e.next_correction_bar.size() == 0 || e.next_correction_bar.isZero());
  if (untouched) return {};
  const int primary = e.next_tried && !e.trials.empty() ? static_cast<int>(e.trials.size()) - 1 : -1;
  return correction_overlay(e, primary, s.inspector.chosen, s.joint);
}

}  // namespace bellows::ui
