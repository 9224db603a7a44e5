// The numbers the plots show, taken from the experiment: degrees for angles, seconds for time.
#pragma once

#include <string>
#include <vector>

#include "engine/trial/trial_record.hpp"
#include "ui/canvas.hpp"
#include "ui/console_state.hpp"

namespace bellows::ui {

struct TrialSeries {
  std::vector<double> time_s, angle_deg, setpoint_deg;
};
/// Joint `joint`'s angle and set point (0-based; joint 1 by default).
TrialSeries trial_series(const TrialRecord& record, int joint = 0);

struct RmsSeries {
  std::vector<double> iteration, rms_deg;
  std::vector<double> max_error_deg;  // the largest |error| of each iteration (over every joint)
};
/// RMS per iteration over every joint, or joint `joint`'s (-1: over every joint).
RmsSeries rms_series(const Experiment& experiment, int joint = -1);

struct OverlaySeries {
  std::string label;
  Role role;
  char mark;
  std::vector<double> values;
};
/// Corrections over time (s), drawn in order (the main one last, on top).
struct CorrectionOverlay {
  std::vector<double> time_s;
  std::vector<OverlaySeries> series;
};
/// The correction of trial `primary` (-1: the next trial's correction), the one before it and
/// trial `chosen` (-1: none); joint `joint`'s column (0-based).
CorrectionOverlay correction_overlay(const Experiment& experiment, int primary, int chosen, int joint = 0);
/// Joint `joint`'s error e(t) in degrees over samples 0..N (0-based joint; joint 1 by default).
std::vector<double> error_series_deg(const TrialRecord& record, int joint = 0);

/// The samples 1..N where joint `joint`'s |error| peaks (local maxima of |e|), the largest first:
/// what the inspector's e steps through (the largest, then the next ones).
std::vector<int> error_peaks(const TrialRecord& record, int joint = 0);

/// Trial `trial` minus trial `other` (indices into experiment.trials), joint `joint`: the change of
/// the correction (samples 0..N-1) and of the error (samples 0..N), and their RMS (the error's over
/// samples 1..N, as the trial's own RMS). `why` says why not when a record is on disk only.
struct TrialDifference {
  bool available = false;
  std::string why;
  int iteration = 0, other_iteration = 0;
  std::vector<double> du_bar, de_deg;
  double rms_du_bar = 0.0, rms_de_deg = 0.0;
};
TrialDifference trial_difference(const Experiment& experiment, int trial, int other, int joint = 0);

/// The dashboard's view: the next correction when no trial ran with it yet, else the last trial's;
/// the selected joint's.
CorrectionOverlay correction_overlay(const ConsoleState& state);

}  // namespace bellows::ui
