// Issue 23, the study in the inspector and the RMS plot: the error beside the correction, the jump
// to the largest |error| and the next ones, the difference of two compared iterations and its RMS,
// the RMS plot on a log scale; drawn into text.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "tests/ui_sample_state.hpp"
#include "ui/plot.hpp"
#include "ui/plot_data.hpp"
#include "ui/render.hpp"

namespace bellows::ui {
namespace {

using testing::all;
using testing::kDeg;
using testing::sample_state;

TEST(UiStudy, ErrorPeaksAreTheLocalMaximaOfTheAbsoluteErrorLargestFirst) {
  TrialRecord record;
  record.prepare(8, 4);
  // Samples 0..8: sample 0 is before the trajectory and never a peak; |e| peaks at 2 (-3), 5 (2.5), 8 (4).
  const double e[] = {9.0, 1.0, -3.0, 1.0, 2.0, 2.5, 2.5, 1.0, 4.0};
  for (int k = 0; k <= 8; ++k) record.joint_samples(0).error_rad(k) = e[k] * kDeg;
  EXPECT_EQ(error_peaks(record), (std::vector<int>{8, 2, 5}));
  EXPECT_NEAR(error_series_deg(record)[2], -3.0, 1e-12);
}

TEST(UiStudy, TheDifferenceOfTwoIterationsAndItsRms) {
  const ConsoleState s = sample_state(3, false);
  const TrialDifference d = trial_difference(s.experiment, 2, 0, 0);
  ASSERT_TRUE(d.available) << d.why;
  EXPECT_EQ(d.iteration, 2);
  EXPECT_EQ(d.other_iteration, 0);
  // Trial i applies 0.01 i bar everywhere and leaves the error set point * 0.5 / (i + 1).
  EXPECT_NEAR(d.rms_du_bar, 0.02, 1e-12);
  const TrialSamples& r = s.experiment.trials[0].record.joint_samples(0);
  double sum = 0.0;
  for (int k = 1; k <= r.error_rad.size() - 1; ++k) {
    const double de = r.setpoint_rad(k) * (0.5 / 3 - 0.5) / kDeg;
    sum += de * de;
  }
  EXPECT_NEAR(d.rms_de_deg, std::sqrt(sum / static_cast<double>(r.error_rad.size() - 1)), 1e-9);
  EXPECT_FALSE(trial_difference(s.experiment, 1, 1, 0).available);
}

TEST(UiStudy, TheInspectorShowsTheErrorBesideTheCorrectionAndTheComparison) {
  for (auto [w, h] : {std::pair{80, 24}, std::pair{120, 40}}) {
    ConsoleState s = sample_state(3, false);
    s.width = w;
    s.height = h;
    s.screen = Screen::kInspector;
    s.inspector = {2, 200, 0};
    const std::vector<std::string> lines = render_lines(s);
    const std::string text = all(lines);
    EXPECT_NE(text.find(w >= 120 ? "u_ilc (bar)" : "Correction u_ilc (bar)"), std::string::npos) << text;
    EXPECT_NE(text.find("Error e (deg)"), std::string::npos) << text;
    EXPECT_NE(text.find("Angle and set point (deg)"), std::string::npos) << text;
    // The compared iteration: its error beside this one's, and the differences.
    EXPECT_NE(text.find("o it 0"), std::string::npos) << text;
    EXPECT_NE(text.find("RMS du     0.0200 bar"), std::string::npos) << text;
    const TrialDifference d = trial_difference(s.experiment, 2, 0, 0);
    EXPECT_NE(text.find(format("RMS de     %.3f deg", d.rms_de_deg)), std::string::npos) << text;
    // Side by side when there is room: the correction's and the error's frames on one row.
    const auto both = std::find_if(lines.begin(), lines.end(), [](const std::string& l) {
      return l.find("u_ilc (bar)") != std::string::npos && l.find("Error e") != std::string::npos;
    });
    EXPECT_EQ(both != lines.end(), w >= 120) << text;
  }
}

TEST(UiStudy, TheReadoutNamesTheErrorPeakTheCursorIsOn) {
  ConsoleState s = sample_state(3, false);
  s.width = 80;
  s.height = 24;
  s.screen = Screen::kInspector;
  const std::vector<int> peaks = error_peaks(s.experiment.trials[1].record);
  ASSERT_GE(peaks.size(), 2u);
  s.inspector = {1, peaks[1], -1, 1};
  const std::string text = all(render_lines(s));
  EXPECT_NE(text.find(format("|e| peak   2 of %zu", peaks.size())), std::string::npos) << text;
  EXPECT_NE(text.find(format("sample     %d / 400", peaks[1])), std::string::npos) << text;
  s.inspector.sample = peaks[1] + 1;  // moved off it: no claim
  EXPECT_EQ(all(render_lines(s)).find("|e| peak"), std::string::npos);
}

TEST(UiStudy, ALogScaleLabelsItsAxisWithTheValues) {
  Canvas c(40, 6);
  const std::vector<double> x = {0, 1, 2}, y = {1, 10, 100};
  PlotOptions options;
  options.braille = false;
  options.log_y = true;
  options.y_min = 1.0;
  options.y_max = 100.0;
  draw_plot(c, {0, 0, 40, 6}, {{x, y, Role::kSeries1, '*'}}, options);
  const std::vector<std::string> lines = c.lines();
  EXPECT_NE(lines[0].find("100.0"), std::string::npos) << all(lines);
  EXPECT_NE(lines[2].find("10.0"), std::string::npos) << all(lines);  // the middle of a log axis
  EXPECT_NE(lines[4].find("1.0"), std::string::npos) << all(lines);
  // The middle point (x = 1: column 7 + 1 + 16) sits on the middle row; a linear axis puts it at the bottom.
  EXPECT_EQ(lines[2][24], '*') << all(lines);
  options.log_y = false;
  Canvas linear(40, 6);
  draw_plot(linear, {0, 0, 40, 6}, {{x, y, Role::kSeries1, '*'}}, options);
  EXPECT_EQ(linear.lines()[4][24], '*') << all(linear.lines());
}

TEST(UiStudy, TheRmsPlotOnALogScaleWithTheLargestErrorBesideIt) {
  ConsoleState s = sample_state(4, false);
  s.rms_log_scale = true;
  const std::string text = all(render_lines(s));
  EXPECT_NE(text.find("RMS per iteration (deg), log"), std::string::npos) << text;
  EXPECT_NE(text.find("x max|e|"), std::string::npos) << text;
  s.rms_log_scale = false;
  EXPECT_EQ(all(render_lines(s)).find(", log"), std::string::npos);
}

}  // namespace
}  // namespace bellows::ui
