// The correction inspector (a cursor along time and across iterations) and the fault screen (the
// guard that fired and the black box around it): the two screens that read recorded signals.
#include <algorithm>

#include "ui/joint_view.hpp"
#include "ui/plot.hpp"
#include "ui/plot_data.hpp"
#include "ui/render_parts.hpp"

namespace bellows::ui::detail {
namespace {

struct ReadoutRow {
  std::string label, value;
  int priority;  // rows that do not fit go, the highest number first
  Role role = Role::kNormal;
};

/// The readout beside the plots: as many rows as fit, the most important kept, in their order.
void readout(Canvas& c, const Rect& in, std::vector<ReadoutRow> rows) {
  while (static_cast<int>(rows.size()) > in.height && !rows.empty()) {
    rows.erase(std::max_element(rows.begin(), rows.end(),
                                [](const auto& a, const auto& b) { return a.priority < b.priority; }));
  }
  int y = in.y;
  for (const ReadoutRow& r : rows) {
    c.put(in.x + 1, y, r.label, Role::kDim, false, in.right());
    c.put(in.x + 12, y++, r.value, r.role, true, in.right());
  }
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
  const int joint = selected_joint(s) < t.record.joint_count() ? selected_joint(s) : 0;
  const TrialSamples& samples = t.record.joint_samples(joint);
  const int k = std::clamp(s.inspector.sample, 0, static_cast<int>(t.record.sample_time_s.size()) - 1);
  const double cursor_s = t.record.sample_time_s(k);
  const int chosen = s.inspector.chosen;
  const TrialDifference diff = trial_difference(e, s.inspector.trial, chosen, joint);

  int x = c.put(body.x + 1, body.y, format("Iteration %d", t.iteration), Role::kTitle, true);
  x = c.put(x, body.y, format(" of 0..%d", e.trials.back().iteration), Role::kDim);
  if (t.record.joint_count() > 1)
    x = c.put(x + 2, body.y, joint_label(t.record.joint_count(), joint), Role::kNormal, true);
  x = c.put(x + 2, body.y, "(" + t.origin + ")", Role::kDim);
  x = c.put(x + 2, body.y, format("RMS %.3f deg", t.summary.rms_deg), Role::kNormal, true);
  if (joint < t.summary.joint_rms_deg.size() && t.record.joint_count() > 1) {
    x = c.put(x + 1, body.y, format("(joint %d %.3f)", joint + 1, t.summary.joint_rms_deg(joint)), Role::kNormal);
  }
  if (chosen >= 0) c.put(x + 2, body.y, format("overlay: it %d", chosen), Role::kSeries3);

  // The correction and the error it left side by side when there is room, else one above the other;
  // the angle against its set point below.
  constexpr int kReadoutWidth = 30;
  const Rect plots{body.x, body.y + 1, body.width - kReadoutWidth, body.height - 1};
  const bool side_by_side = plots.width >= 80;
  const int rows = side_by_side ? 2 : 3;
  const int row_height = plots.height / rows;
  const Rect correction_area{plots.x, plots.y, side_by_side ? plots.width / 2 : plots.width, row_height};
  const Rect error_area = side_by_side
                              ? Rect{correction_area.right(), plots.y, plots.width - correction_area.width, row_height}
                              : Rect{plots.x, plots.y + row_height, plots.width, row_height};
  const int angle_y = plots.y + row_height * (rows - 1);
  const Rect angle_area{plots.x, angle_y, plots.width, plots.bottom() - angle_y};

  PlotOptions options;
  options.braille = s.unicode;
  options.x_unit = "s";
  options.cursor_x = cursor_s;

  c.frame(correction_area, g, side_by_side ? "u_ilc (bar)" : "Correction u_ilc (bar)");  // the legend needs the room
  const CorrectionOverlay overlay = correction_overlay(e, s.inspector.trial, chosen, joint);
  std::vector<LegendItem> items;
  std::vector<PlotSeries> series;
  for (const auto& o : overlay.series) {
    items.push_back({o.label, o.role, o.mark});
    series.push_back({overlay.time_s, o.values, o.role, o.mark});
  }
  legend(c, correction_area, items, g);
  options.y_format = "%.3f";
  draw_plot(c, inner(correction_area), series, options);

  // The error e(t) = set point - angle, and the compared iteration's (m) beside it.
  c.frame(error_area, g, "Error e (deg)");
  const TrialSeries data = trial_series(t.record, joint);
  const std::vector<double> error_deg = error_series_deg(t.record, joint);
  std::vector<double> chosen_error_deg;
  std::vector<LegendItem> error_items;
  std::vector<PlotSeries> error_plot;
  if (diff.available) {
    chosen_error_deg = error_series_deg(e.trials[static_cast<std::size_t>(chosen)].record, joint);
    error_items.push_back({"it " + std::to_string(diff.other_iteration), Role::kSeries3, 'o'});
    error_plot.push_back({data.time_s, chosen_error_deg, Role::kSeries3, 'o'});
  }
  error_items.push_back({"it " + std::to_string(t.iteration), Role::kSeries1, '*'});
  error_plot.push_back({data.time_s, error_deg, Role::kSeries1, '*'});
  legend(c, error_area, error_items, g);
  options.y_format = "%.2f";
  draw_plot(c, inner(error_area), error_plot, options);

  c.frame(angle_area, g, "Angle and set point (deg)");
  legend(c, angle_area, {{"angle", Role::kSeries1, '*'}, {"set point", Role::kSeries2, '.'}}, g);
  options.y_format = "%.1f";
  draw_plot(c, inner(angle_area),
            {{data.time_s, data.setpoint_deg, Role::kSeries2, '.'}, {data.time_s, data.angle_deg, Role::kSeries1, '*'}},
            options);

  // The readout: the values at the cursor, which |error| peak it is on (e), the differences to the
  // compared iteration (m).
  std::vector<ReadoutRow> rows_shown = {
      {"iteration", format("%d", t.iteration), 1},
      {"sample", format("%d / %d", k, t.record.learning_samples), 1},
      {"time", format("%.2f s", cursor_s), 1},
      {"set point", number("%.2f deg", to_deg(samples.setpoint_rad(k))), 2},
      {"angle", number("%.2f deg", to_deg(samples.angle_rad(k))), 2},
      {"error", number("%.2f deg", to_deg(samples.error_rad(k))), 1},
      {"u_pid", number("%.4f bar", samples.u_pid_bar(k)), 4},
      {"u_ilc", number("%.4f bar", samples.u_ilc_bar(k)), 2},
      {"p A", number("%.3f bar", samples.pressure_a_bar(k)), 5},
      {"p B", number("%.3f bar", samples.pressure_b_bar(k)), 5},
  };
  const std::vector<int> peaks = s.inspector.peak >= 0 ? error_peaks(t.record, joint) : std::vector<int>{};
  if (s.inspector.peak >= 0 && s.inspector.peak < static_cast<int>(peaks.size()) &&
      peaks[static_cast<std::size_t>(s.inspector.peak)] == k) {
    rows_shown.insert(
        rows_shown.begin() + 6,
        ReadoutRow{"|e| peak", format("%d of %zu", s.inspector.peak + 1, peaks.size()), 1, Role::kWarning});
  }
  if (diff.available) {
    const auto du_at = static_cast<std::size_t>(std::min(k, static_cast<int>(diff.du_bar.size()) - 1));
    const std::string vs = format(" vs %d", diff.other_iteration);
    rows_shown.push_back({"du" + vs, number("%.4f bar", diff.du_bar[du_at]), 3, Role::kSeries3});
    rows_shown.push_back({"de" + vs, number("%.2f deg", diff.de_deg[static_cast<std::size_t>(k)]), 3, Role::kSeries3});
    rows_shown.push_back({"RMS du", number("%.4f bar", diff.rms_du_bar), 2, Role::kSeries3});
    rows_shown.push_back({"RMS de", number("%.3f deg", diff.rms_de_deg), 2, Role::kSeries3});
  } else if (chosen >= 0 && chosen != s.inspector.trial) {
    rows_shown.push_back({"compare", diff.why, 3, Role::kDim});
  }
  const int wanted = static_cast<int>(rows_shown.size()) + 2;
  const Rect readout_area{plots.right(), body.y + 1, kReadoutWidth, std::min(body.height - 1, wanted)};
  c.frame(readout_area, g, "At the cursor");
  readout(c, inner(readout_area), std::move(rows_shown));
  int y = readout_area.bottom();
  for (const char* hint : {"e worst |error|, E back", "m compare this iteration", "u use its correction next"}) {
    if (y + 1 > body.bottom()) break;
    c.put(readout_area.x + 1, y++, hint, Role::kDim);
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
  for (const std::string& line :
       wrap(f.detail.empty() ? std::string(fault_message(f.code)) : f.detail, body.right() - x - 2)) {
    c.put(x + 1, y++, line, Role::kWarning, true);
  }
  if (!f.where.empty()) {  // which joint (and chamber), on an arm with several
    for (const std::string& line : wrap("on " + f.where, body.right() - x - 2))
      c.put(x + 1, y++, line, Role::kWarning, true);
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
            {{time, supply, Role::kSeries3, 's'}, {time, pb, Role::kSeries2, 'b'}, {time, pa, Role::kSeries1, 'a'}},
            options);

  const Rect table{body.x, left.bottom(), body.width, body.bottom() - left.bottom()};
  c.frame(table, g, "Last ticks before the fault" + of_joint);
  const Rect in = inner(table);
  c.put(in.x + 1, in.y, "  time s   state      angle deg  p A bar  p B bar  supply  in A  out A  in B  out B",
        Role::kDim);
  const std::size_t rows = static_cast<std::size_t>(std::max(in.height - 1, 0));
  const std::size_t first = n > rows ? n - rows : 0;
  for (std::size_t i = first; i < n; ++i) {
    const TickRecord& t = f.black_box[i];
    c.put(
        in.x + 1, in.y + 1 + static_cast<int>(i - first),
        format("%8.3f   %-9s %9.2f %8.3f %8.3f %7.3f %5.2f %6.2f %5.2f %6.2f", t.time_s - f.time_s, to_string(t.state),
               to_deg(t.reading.joint[ji].angle_rad), t.reading.joint[ji].chamber_bar[0],
               t.reading.joint[ji].chamber_bar[1], t.reading.supply_bar, t.valves.joint[ji].inlet_duty[0],
               t.valves.joint[ji].outlet_duty[0], t.valves.joint[ji].inlet_duty[1], t.valves.joint[ji].outlet_duty[1]),
        t.state == EngineState::kFault ? Role::kFault : Role::kNormal, false, in.right());
  }
}

}  // namespace bellows::ui::detail
