// The correction inspector (a cursor along time and across iterations) and the fault screen (the
// guard that fired and the black box around it): the two screens that read recorded signals.
#include <algorithm>

#include "ui/joint_view.hpp"
#include "ui/plot.hpp"
#include "ui/plot_data.hpp"
#include "ui/render_parts.hpp"

namespace bellows::ui::detail {
namespace {

void readout_row(Canvas& c, const Rect& in, int& row, const std::string& label, const std::string& value) {
  if (row >= in.height) return;
  c.put(in.x + 1, in.y + row, label, Role::kDim, false, in.right());
  c.put(in.x + 12, in.y + row, value, Role::kNormal, true, in.right());
  ++row;
}

}  // namespace

void render_inspector(const ConsoleState& s, Canvas& c, const Rect& body) {
  const Glyphs g = Glyphs::for_unicode(s.unicode);
  const Experiment& e = s.experiment;
  if (e.trials.empty() || s.inspector.trial < 0 || s.inspector.trial >= static_cast<int>(e.trials.size())) {
    c.put(body.x + 2, body.y + 1, "No trial yet: the inspector shows recorded trials.", Role::kDim);
    return;
  }
  const Trial& t = e.trials[static_cast<std::size_t>(s.inspector.trial)];
  if (!t.in_memory()) {
    c.put(body.x + 1, body.y, format("Iteration %d", t.iteration), Role::kTitle, true);
    c.put(body.x + 2, body.y + 1,
          format("RMS %.3f deg. Its record is in the session on disk only: the console keeps the newest %d trials in "
                 "memory (bellows sessions show / export).",
                 t.summary.rms_deg, Experiment::kTrialsKeptInMemory),
          Role::kDim, false, body.right());
    return;
  }
  // The selected joint's signals (j selects; joint 1 of a record that has fewer joints).
  const int joint = selected_joint(s) < t.record.joints() ? selected_joint(s) : 0;
  const TrialSamples& samples = t.record.joint_samples(joint);
  const int k = std::clamp(s.inspector.sample, 0, static_cast<int>(samples.time_s.size()) - 1);
  const double cursor_s = samples.time_s(k);

  int x = c.put(body.x + 1, body.y, format("Iteration %d", t.iteration), Role::kTitle, true);
  x = c.put(x, body.y, format(" of 0..%d", e.trials.back().iteration), Role::kDim);
  if (t.record.joints() > 1) x = c.put(x + 2, body.y, joint_label(t.record.joints(), joint), Role::kNormal, true);
  x = c.put(x + 2, body.y, "(" + t.origin + ")", Role::kDim);
  x = c.put(x + 2, body.y, format("RMS %.3f deg", t.summary.rms_deg), Role::kNormal, true);
  if (joint < t.summary.joint_rms_deg.size() && t.record.joints() > 1) {
    x = c.put(x + 1, body.y, format("(joint %d %.3f)", joint + 1, t.summary.joint_rms_deg(joint)), Role::kNormal);
  }
  if (s.inspector.chosen >= 0) c.put(x + 2, body.y, format("overlay: it %d", s.inspector.chosen), Role::kSeries3);

  constexpr int kReadoutWidth = 30;
  const Rect plots{body.x, body.y + 1, body.width - kReadoutWidth, body.height - 1};
  const int top_height = plots.height / 2;
  const Rect top{plots.x, plots.y, plots.width, top_height};
  const Rect bottom{plots.x, plots.y + top_height, plots.width, plots.height - top_height};

  PlotOptions options;
  options.braille = s.unicode;
  options.x_unit = "s";
  options.cursor_x = cursor_s;

  c.frame(top, g, "Correction u_ilc (bar)");
  const CorrectionOverlay overlay = correction_overlay(e, s.inspector.trial, s.inspector.chosen, joint);
  std::vector<LegendItem> items;
  std::vector<PlotSeries> series;
  for (const auto& o : overlay.series) {
    items.push_back({o.label, o.role, o.mark});
    series.push_back({overlay.time_s, o.values, o.role, o.mark});
  }
  legend(c, top, items, g);
  options.y_format = "%.3f";
  draw_plot(c, inner(top), series, options);

  c.frame(bottom, g, "Angle and set point (deg)");
  legend(c, bottom, {{"angle", Role::kSeries1, '*'}, {"set point", Role::kSeries2, '.'}}, g);
  const TrialSeries data = trial_series(t.record, joint);
  options.y_format = "%.1f";
  draw_plot(c, inner(bottom),
            {{data.time_s, data.setpoint_deg, Role::kSeries2, '.'}, {data.time_s, data.angle_deg, Role::kSeries1, '*'}},
            options);

  const Rect readout{plots.right(), body.y + 1, kReadoutWidth, std::min(body.height - 1, 14)};
  c.frame(readout, g, "At the cursor");
  const Rect in = inner(readout);
  int row = 0;
  readout_row(c, in, row, "iteration", format("%d", t.iteration));
  readout_row(c, in, row, "sample", format("%d / %d", k, t.record.learning_samples));
  readout_row(c, in, row, "time", format("%.2f s", cursor_s));
  readout_row(c, in, row, "set point", number("%.2f deg", to_deg(samples.setpoint_rad(k))));
  readout_row(c, in, row, "angle", number("%.2f deg", to_deg(samples.angle_rad(k))));
  readout_row(c, in, row, "error", number("%.2f deg", to_deg(samples.error_rad(k))));
  readout_row(c, in, row, "u_pid", number("%.4f bar", samples.u_pid_bar(k)));
  readout_row(c, in, row, "u_ilc", number("%.4f bar", samples.u_ilc_bar(k)));
  readout_row(c, in, row, "p A", number("%.3f bar", samples.pressure_a_bar(k)));
  readout_row(c, in, row, "p B", number("%.3f bar", samples.pressure_b_bar(k)));
  if (readout.bottom() + 3 <= body.bottom()) {
    const int y = readout.bottom();
    c.put(readout.x + 1, y, "m overlay this iteration", Role::kDim);
    c.put(readout.x + 1, y + 1, "u use its correction next", Role::kDim);
  }
}

void render_fault(const ConsoleState& s, Canvas& c, const Rect& body) {
  const Glyphs g = Glyphs::for_unicode(s.unicode);
  const FaultView& f = s.fault_view;
  if (f.code == FaultCode::kNone) {
    c.put(body.x + 2, body.y + 1, "No fault so far.", Role::kDim);
    return;
  }
  // The guard and what it means, then when it vented: wrapped, never cut off.
  int y = body.y;
  const int x = c.put(body.x + 1, y, format(" %s ", fault_name(f.code)), Role::kFault, true);
  for (const std::string& line : wrap(f.detail.empty() ? std::string(fault_message(f.code)) : f.detail, body.right() - x - 2)) {
    c.put(x + 1, y++, line, Role::kWarning, true);
  }
  if (!f.where.empty()) {  // which joint (and chamber), on an arm with several
    for (const std::string& line : wrap("on " + f.where, body.right() - x - 2)) c.put(x + 1, y++, line, Role::kWarning, true);
  }
  const bool latched = s.engine_state == EngineState::kFault;
  const std::string when = format("vented at engine time %.3f s, in the tick the fault was seen; %s", f.time_s,
                                  latched ? "latched: R resets to SAFE, then a arms again." : "reset since then.");
  for (const std::string& line : wrap(when, body.width - 2)) {
    c.put(body.x + 1, y++, line, latched ? Role::kNormal : Role::kDim);
  }
  if (f.black_box.empty()) {
    c.put(body.x + 1, y + 1, "The black box was not captured.", Role::kDim);
    return;
  }
  const std::size_t n = f.black_box.size();
  // The selected joint's signals on an arm with several joints (j selects).
  const int joint = std::clamp(selected_joint(s), 0, std::max(1, f.black_box.back().reading.joint_count) - 1);
  const auto ji = static_cast<std::size_t>(joint);
  std::vector<double> time(n), angle(n), desired(n), pa(n), pb(n), supply(n);
  for (std::size_t i = 0; i < n; ++i) {
    const TickRecord& t = f.black_box[i];
    time[i] = t.time_s - f.time_s;
    angle[i] = to_deg(t.reading.joint[ji].angle_rad);
    desired[i] = to_deg(tick_desired_rad(t, joint));
    pa[i] = t.reading.joint[ji].chamber_bar[0];
    pb[i] = t.reading.joint[ji].chamber_bar[1];
    supply[i] = t.reading.supply_bar;
  }
  const int joints = f.black_box.back().reading.joint_count;
  const std::string of_joint = joints > 1 ? ", " + joint_label(joints, joint) : std::string();
  constexpr int kTableRows = 8;
  const int plot_height = std::max(6, body.bottom() - y - (kTableRows + 3));
  const Rect left{body.x, y, body.width / 2, plot_height};
  const Rect right{left.right(), left.y, body.width - left.width, plot_height};
  PlotOptions options;
  options.braille = s.unicode;
  options.x_unit = "s";
  c.frame(left, g, format("Black box: last %.1f s, angle (deg)%s", time.back() - time.front(), of_joint.c_str()));
  legend(c, left, {{"angle", Role::kSeries1, '*'}, {"set pt", Role::kSeries2, '.'}}, g);
  draw_plot(c, inner(left), {{time, desired, Role::kSeries2, '.'}, {time, angle, Role::kSeries1, '*'}}, options);
  c.frame(right, g, "Pressures (bar)" + of_joint);
  legend(c, right, {{"A", Role::kSeries1, 'a'}, {"B", Role::kSeries2, 'b'}, {"supply", Role::kSeries3, 's'}}, g);
  options.y_format = "%.2f";
  draw_plot(c, inner(right),
            {{time, supply, Role::kSeries3, 's'}, {time, pb, Role::kSeries2, 'b'}, {time, pa, Role::kSeries1, 'a'}}, options);

  const Rect table{body.x, left.bottom(), body.width, body.bottom() - left.bottom()};
  c.frame(table, g, "Last ticks before the fault" + of_joint);
  const Rect in = inner(table);
  c.put(in.x + 1, in.y, "  time s   state      angle deg  p A bar  p B bar  supply  in A  out A  in B  out B", Role::kDim);
  const std::size_t rows = static_cast<std::size_t>(std::max(in.height - 1, 0));
  const std::size_t first = n > rows ? n - rows : 0;
  for (std::size_t i = first; i < n; ++i) {
    const TickRecord& t = f.black_box[i];
    c.put(in.x + 1, in.y + 1 + static_cast<int>(i - first),
          format("%8.3f   %-9s %9.2f %8.3f %8.3f %7.3f %5.2f %6.2f %5.2f %6.2f", t.time_s - f.time_s, to_string(t.state),
                 to_deg(t.reading.joint[ji].angle_rad), t.reading.joint[ji].chamber_bar[0], t.reading.joint[ji].chamber_bar[1], t.reading.supply_bar,
                 t.valves.joint[ji].inlet_duty[0], t.valves.joint[ji].outlet_duty[0], t.valves.joint[ji].inlet_duty[1], t.valves.joint[ji].outlet_duty[1]),
          t.state == EngineState::kFault ? Role::kFault : Role::kNormal, false, in.right());
  }
}

}  // namespace bellows::ui::detail
