// The main screen: live values and valve duty cycles, the last trial against its set point, RMS
// per iteration, the correction (with the previous and a chosen iteration), the newest log lines.
#include <algorithm>

#include "ui/joint_view.hpp"
#include "ui/plot.hpp"
#include "ui/plot_data.hpp"
#include "ui/render_parts.hpp"

namespace bellows::ui::detail {
namespace {

void value_row(Canvas& c, const Rect& area, int row, const std::string& label, const std::string& value,
               Role role = Role::kNormal) {
  if (row >= area.height) return;
  c.put(area.x + 1, area.y + row, label, Role::kDim, false, area.right());
  c.put(area.x + 12, area.y + row, value, role, true, area.right());
}

void duty_row(Canvas& c, const Rect& area, int row, const std::string& label, double duty, const Glyphs& g) {
  if (row >= area.height) return;
  const int bar_width = std::max(4, area.width - 13);
  c.put(area.x + 1, area.y + row, label, Role::kDim, false, area.right());
  c.put(area.x + 7, area.y + row, bar(duty, bar_width, g), Role::kSeries1, false, area.right());
  c.put(area.x + 8 + bar_width, area.y + row, format("%3.0f%%", 100.0 * duty), Role::kNormal, false, area.right());
}

std::string run_phase_text(const ConsoleState& s) {
  const RunProgress& r = s.run;
  switch (r.phase) {
    case RunProgress::Phase::kLearning:
      return "learning";
    case RunProgress::Phase::kSettling:
      return "settling at the start";
    case RunProgress::Phase::kRunning:
      if (s.experiment.trajectory) {
        return format("running %.1f / %.1f s", std::max(r.sample, 0) * s.experiment.trajectory->sample_time_s,
                      s.experiment.trajectory->duration_s());
      }
      return "running";
    case RunProgress::Phase::kNone:
      break;
  }
  return "idle";
}

/// " joint 2/2 elbow" on an arm with several joints, "" with one (the titles stay as they were).
std::string joint_suffix(const ConsoleState& s) {
  const int joints = s.experiment.joints();
  return joints > 1 ? ", " + joint_label(joints, selected_joint(s)) : std::string();
}

void render_live(const ConsoleState& s, Canvas& c, const Rect& area, const Glyphs& g) {
  c.frame(area, g, "Live" + joint_suffix(s));
  const Rect in = inner(area);
  if (!s.live_valid) {
    c.put(in.x + 1, in.y, "waiting for the engine", Role::kDim);
    return;
  }
  const TickRecord& t = s.live;
  const int j = selected_joint(s);
  const JointReading& joint = t.reading.joint[static_cast<std::size_t>(j)];
  const JointValves& valves = t.valves.joint[static_cast<std::size_t>(j)];
  const double desired_rad = tick_desired_rad(t, j);
  int row = 0;
  value_row(c, in, row++, "angle", number("%7.2f deg", to_deg(joint.angle_rad)));
  // The latest tick's own state, not the console's: the engine keeps its last set point after a
  // vent, which is no set point at all then, and a tracking error exists only during a trial.
  if (valves_live(t.state)) {
    value_row(c, in, row++, "set point",
              number("%7.2f deg", to_deg(desired_rad)) + (t.state == EngineState::kArmed ? " hold" : ""));
  } else {
    value_row(c, in, row++, "set point", "none: vented", Role::kDim);
  }
  if (t.state == EngineState::kRunning) {
    value_row(c, in, row++, "error", number("%7.2f deg", to_deg(desired_rad - joint.angle_rad)));
  } else {
    value_row(c, in, row++, "error", "no trial", Role::kDim);
  }
  value_row(c, in, row++, "p A", number("%7.3f bar", joint.chamber_bar[0]));
  value_row(c, in, row++, "p B", number("%7.3f bar", joint.chamber_bar[1]));
  value_row(c, in, row++, "supply", number("%7.3f bar", t.reading.supply_bar),
            t.reading.supply_bar < s.config.safety.supply_min_bar ? Role::kWarning : Role::kNormal);
  duty_row(c, in, row++, "in A", valves.inlet_duty[0], g);
  duty_row(c, in, row++, "out A", valves.outlet_duty[0], g);
  duty_row(c, in, row++, "in B", valves.inlet_duty[1], g);
  duty_row(c, in, row++, "out B", valves.outlet_duty[1], g);
  value_row(c, in, row++, "trial", run_phase_text(s),
            s.run.phase == RunProgress::Phase::kNone ? Role::kDim : Role::kRunning);
  if (s.run.mode == RunProgress::Mode::kBatch) {
    value_row(c, in, row++, "batch",
              format("it %s, %d done%s", batch_span(s.run).c_str(), s.run.batch_done,
                     s.run.stop_requested ? ", stopping" : ""));
  } else {
    value_row(c, in, row++, "next", s.experiment.next_origin, Role::kDim);
  }
}

void render_trial_plot(const ConsoleState& s, Canvas& c, const Rect& area, const Glyphs& g) {
  const Rect in = inner(area);
  const bool running = s.run.phase == RunProgress::Phase::kRunning || s.run.phase == RunProgress::Phase::kSettling;
  PlotOptions options;
  options.braille = s.unicode;
  options.x_unit = "s";
  if (!running && !s.experiment.trials.empty()) {
    const Trial& t = s.experiment.trials.back();
    c.frame(area, g, format("Iteration %d%s: angle and set point (deg)", t.iteration, joint_suffix(s).c_str()));
    legend(c, area, {{"angle", Role::kSeries1, '*'}, {"set point", Role::kSeries2, '.'}}, g);
    const TrialSeries data = trial_series(t.record, selected_joint(s));
    draw_plot(
        c, in,
        {{data.time_s, data.angle_deg, Role::kSeries1, '*'}, {data.time_s, data.setpoint_deg, Role::kSeries2, '.'}},
        options);
    return;
  }
  c.frame(area, g, "Live" + joint_suffix(s) + ": angle and set point (deg), last seconds");
  legend(c, area, {{"angle", Role::kSeries1, '*'}, {"set point", Role::kSeries2, '.'}}, g);
  if (s.strip.time_s.size() < 2) {
    c.put(in.x + 1, in.y, "no trial yet: arm (a), then run a trial (r) or an iteration (n)", Role::kDim, false,
          in.right());
    return;
  }
  draw_plot(c, in,
            {{s.strip.time_s, s.strip.angle_deg, Role::kSeries1, '*'},
             {s.strip.time_s, s.strip.setpoint_deg, Role::kSeries2, '.'}},
            options);
}

void render_rms(const ConsoleState& s, Canvas& c, const Rect& area, const Glyphs& g) {
  const std::string title = s.experiment.joints() > 1
                                ? "RMS per iteration (deg), all joints and j" + std::to_string(selected_joint(s) + 1)
                                : std::string("RMS per iteration (deg)") + (s.rms_log_scale ? ", log" : "");
  c.frame(area, g, title);
  const Rect in = inner(area);
  const auto& trials = s.experiment.trials;
  if (trials.empty()) {
    c.put(in.x + 1, in.y, "no iteration yet", Role::kDim, false, in.right());
    return;
  }
  // With several joints: the RMS over every joint and sample, then each joint's (docs/console.md).
  const int joints = s.experiment.joints();
  // A law that learns its model (noilc-learned): how far each trial's measured change of error was
  // from what the model that planned it predicted, beside the RMS (docs/console.md).
  const bool model_checks = std::any_of(trials.begin(), trials.end(), [](const Trial& t) { return t.model_check; });
  const int check_width = model_checks ? 6 : 0;                              // " %4.0f%%"
  const int list_width = (joints > 1 ? 13 + 7 * joints : 15) + check_width;  // "%4d %9.3f" and the best mark '*'
  const Rect list{in.right() - list_width, in.y, list_width, in.height};
  if (joints > 1) {
    std::string head = "  it     all ";
    for (int j = 0; j < joints; ++j) head += format("     j%d", j + 1);
    c.put(list.x, list.y, head + (model_checks ? "  miss" : ""), Role::kDim);
  } else {
    c.put(list.x, list.y, model_checks ? "  it       RMS   miss" : "  it       RMS ", Role::kDim);
  }
  const int rows = list.height - 1;
  const int count = static_cast<int>(trials.size());
  const double best = s.experiment.best_rms_deg();
  for (int i = std::max(0, count - rows), y = list.y + 1; i < count; ++i, ++y) {
    const Trial& t = trials[static_cast<std::size_t>(i)];
    const bool is_best = t.summary.rms_deg == best;
    std::string line = joints > 1 ? format("%4d %7.3f%s", t.iteration, t.summary.rms_deg, is_best ? "*" : " ")
                                  : format("%4d %9.3f%s", t.iteration, t.summary.rms_deg, is_best ? "*" : "");
    for (int j = 0; joints > 1 && j < joints; ++j) {
      line += j < t.summary.joint_rms_deg.size() ? format("%7.3f", t.summary.joint_rms_deg(j)) : std::string("      -");
    }
    if (model_checks) {
      if (joints == 1 && !is_best) line += " ";
      line += t.model_check ? format(" %4.0f%%", 100.0 * std::min(t.model_check->miss, 99.99)) : std::string("     -");
    }
    c.put(list.x, y, line, i == count - 1 ? Role::kNormal : Role::kDim, i == count - 1, list.right());
  }
  const Rect plot{in.x, in.y, in.width - list_width - 1, in.height};
  if (plot.width >= 18 && count >= 2) {
    const RmsSeries data = rms_series(s.experiment);
    PlotOptions options;
    options.braille = s.unicode;
    options.integer_x = true;
    options.log_y = s.rms_log_scale;  // L: a log scale shows the late iterations' progress too
    if (!options.log_y) options.y_min = 0.0;
    options.y_format = "%.2f";
    std::vector<PlotSeries> series;
    // The largest |error| of each iteration beside its RMS (over every joint), drawn under it.
    series.push_back({data.iteration, data.max_error_deg, Role::kSeries3, 'x'});
    // Its legend on the frame's bottom edge: the top one holds the title.
    legend(c, {area.x, area.bottom() - 1, area.width, 1},
           {{"RMS", Role::kSeries1, '*'}, {"max|e|", Role::kSeries3, 'x'}}, g);
    const RmsSeries joint =
        joints > 1 ? rms_series(s.experiment, selected_joint(s)) : RmsSeries{};  // the series refer to it
    if (joints > 1) series.push_back({joint.iteration, joint.rms_deg, Role::kSeries2, '.'});
    series.push_back({data.iteration, data.rms_deg, Role::kSeries1, '*'});
    draw_plot(c, plot, series, options);
  }
}

void render_correction(const ConsoleState& s, Canvas& c, const Rect& area, const Glyphs& g) {
  c.frame(area, g, "Correction u_ilc (bar)" + joint_suffix(s));
  const Rect in = inner(area);
  const CorrectionOverlay overlay = correction_overlay(s);
  if (overlay.series.empty()) {
    c.put(in.x + 1, in.y, "zero until the first iteration learns", Role::kDim, false, in.right());
    return;
  }
  std::vector<LegendItem> items;
  std::vector<PlotSeries> series;
  for (const auto& o : overlay.series) {
    items.push_back({o.label, o.role, o.mark});
    series.push_back({overlay.time_s, o.values, o.role, o.mark});
  }
  legend(c, area, items, g);
  PlotOptions options;
  options.braille = s.unicode;
  options.x_unit = "s";
  options.y_format = "%.3f";
  draw_plot(c, in, series, options);
}

}  // namespace

void render_dashboard(const ConsoleState& s, Canvas& c, const Rect& body) {
  const Glyphs g = Glyphs::for_unicode(s.unicode);
  const int left_width = std::clamp(body.width * 3 / 10, 30, 64);
  const int live_height = std::min(14, body.height - 5);
  render_live(s, c, {body.x, body.y, left_width, live_height}, g);
  const Rect log{body.x, body.y + live_height, left_width, body.height - live_height};
  c.frame(log, g, "Log");
  render_log_lines(s, c, {log.x + 1, log.y + 1, log.width - 2, log.height - 2});

  const Rect right{body.x + left_width, body.y, body.width - left_width, body.height};
  const int trial_height = right.height / 2;
  render_trial_plot(s, c, {right.x, right.y, right.width, trial_height}, g);
  const Rect bottom{right.x, right.y + trial_height, right.width, right.height - trial_height};
  // Several joints' RMS columns need more room (the correction keeps at least 30 columns).
  const int rms_width = s.experiment.joints() > 1
                            ? std::clamp(bottom.width * 3 / 5, 22, std::max(22, bottom.width - 30))
                            : std::clamp(bottom.width / 2, 22, 50);
  render_rms(s, c, {bottom.x, bottom.y, rms_width, bottom.height}, g);
  render_correction(s, c, {bottom.x + rms_width, bottom.y, bottom.width - rms_width, bottom.height}, g);
}

}  // namespace bellows::ui::detail
