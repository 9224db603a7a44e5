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
/// The dashboard's view: the next correction when no trial ran with it yet, else the last trial's;
/// the selected joint's.
CorrectionOverlay correction_overlay(const ConsoleState& state);

}  // namespace bellows::ui
