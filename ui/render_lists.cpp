// The list screens: help, trajectory chooser (with its preview), tuning, event log, sessions.
#include <algorithm>
#include <cmath>

#include "engine/base/errors.hpp"
#include "engine/base/iteration_numbering.hpp"
#include "engine/config/learning_law_factory.hpp"
#include "ui/key_map.hpp"
#include "ui/plot.hpp"
#include "ui/render_parts.hpp"
#include "ui/tuning.hpp"

namespace bellows::ui::detail {

namespace {

/// A line of the help as drawn: a section title, or a key (on the first line of its entry only)
/// and a piece of its wrapped description.
struct HelpLine {
  bool section = false;
  bool available = true;
  std::string keys;
  std::string text;
};

constexpr int kHelpKeyColumn = 20;

std::vector<HelpLine> help_layout(const ConsoleState& s, int inner_width) {
  std::vector<HelpLine> lines;
  const int text_columns = std::max(20, inner_width - kHelpKeyColumn - 3);
  for (const HelpEntry& e : help_entries(s)) {
    if (e.section) {
      if (!lines.empty()) lines.push_back({});
      lines.push_back({true, true, "", e.what});
      continue;
    }
    std::string text = e.what;
    if (!e.availability.available && !e.availability.reason.empty()) text += "  (" + e.availability.reason + ")";
    bool first = true;
    for (const std::string& piece : wrap(text, text_columns)) {
      lines.push_back({false, e.availability.available, first ? e.keys : "", piece});
      first = false;
    }
  }
  return lines;
}

}  // namespace

int help_line_count(const ConsoleState& s) { return static_cast<int>(help_layout(s, s.width - 2).size()); }

void render_help(const ConsoleState& s, Canvas& c, const Rect& body) {
  const Glyphs g = Glyphs::for_unicode(s.unicode);
  const Rect in = inner(body);
  const std::vector<HelpLine> lines = help_layout(s, in.width);
  const int total = static_cast<int>(lines.size());
  const int top = std::clamp(s.help_scroll, 0, std::max(0, total - in.height));
  const int shown_last = std::min(total, top + in.height);
  std::string title = "Keys";
  if (total > in.height) title += format(" (lines %d-%d of %d; Up/Down, PgUp/PgDn scroll)", top + 1, shown_last, total);
  c.frame(body, g, title);
  for (int i = top, y = in.y; i < shown_last; ++i, ++y) {
    const HelpLine& l = lines[static_cast<std::size_t>(i)];
    if (l.section) {
      c.put(in.x + 1, y, l.text, Role::kTitle, true, in.right());
      continue;
    }
    if (!l.keys.empty())
      c.put(in.x + 1, y, fit(l.keys, kHelpKeyColumn), l.available ? Role::kKey : Role::kDim, l.available);
    c.put(in.x + 2 + kHelpKeyColumn, y, l.text, l.available ? Role::kNormal : Role::kDim, false, in.right());
  }
}

void render_trajectory(const ConsoleState& s, Canvas& c, const Rect& body) {
  const Glyphs g = Glyphs::for_unicode(s.unicode);
  const TrajectoryChooser& ch = s.chooser;
  const int list_width = std::min(34, body.width / 3);
  const Rect list{body.x, body.y, list_width, body.height};
  c.frame(list, g, "Trajectories");
  const Rect in = inner(list);
  const std::string current = s.experiment.trajectory ? s.experiment.trajectory->name : "";
  for (std::size_t i = 0; i < ch.names.size() && static_cast<int>(i) * 2 < in.height; ++i) {
    const int y = in.y + static_cast<int>(i) * 2;
    const bool selected = static_cast<int>(i) == ch.selected;
    std::string label = ch.names[i];
    if (i + 1 == ch.names.size() && !ch.file_path.empty()) label = "file: " + ch.file_path;
    if (label == current) label += "  (in use)";
    c.put(in.x, y, fit((selected ? "> " : "  ") + label, in.width), selected ? Role::kSelected : Role::kNormal,
          selected);
    if (i < ch.descriptions.size()) c.put(in.x + 2, y + 1, ch.descriptions[i], Role::kDim, false, in.right());
  }
  const Rect preview{list.right(), body.y, body.width - list_width, body.height};
  c.frame(preview, g, "Preview: angle (deg)");
  const Rect pin = inner(preview);
  if (!ch.preview_error.empty()) {
    c.put(pin.x + 1, pin.y, ch.preview_error, Role::kWarning, true, pin.right());
    return;
  }
  if (!ch.preview) {
    c.put(pin.x + 1, pin.y, "Enter: give the path of a CSV file (time_s,angle_deg)", Role::kDim, false, pin.right());
    return;
  }
  const Trajectory& t = *ch.preview;
  const int n = static_cast<int>(t.joint(0).size());
  std::vector<double> time(static_cast<std::size_t>(n)), angle(static_cast<std::size_t>(n));
  double peak_speed = 0.0;
  for (int k = 0; k < n; ++k) {
    time[static_cast<std::size_t>(k)] = k * t.sample_time_s;
    angle[static_cast<std::size_t>(k)] = to_deg(t.joint(0)(k));
    if (k > 0) peak_speed = std::max(peak_speed, std::abs(to_deg(t.joint(0)(k) - t.joint(0)(k - 1))) / t.sample_time_s);
  }
  const auto [lo, hi] = std::minmax_element(angle.begin(), angle.end());
  c.put(pin.x + 1, pin.y,
        format("%s: %.1f s, %d samples, %.1f to %.1f deg, peak speed %.0f deg/s", t.name.c_str(), t.duration_s(),
               t.learning_samples(), *lo, *hi, peak_speed),
        Role::kNormal, true, pin.right());
  PlotOptions options;
  options.braille = s.unicode;
  options.x_unit = "s";
  draw_plot(c, {pin.x, pin.y + 2, pin.width, pin.height - 2}, {{time, angle, Role::kSeries1, '*'}}, options);
}

namespace {

// What the chosen law does; the row's title says how to choose another.
std::string law_summary(const std::string& name) {
  try {
    return learning_law_description(name);
  } catch (const InputError&) {
    return "unknown law";
  }
}

}  // namespace

namespace {

/// How to edit the selected row, and why not now when it cannot change.
std::string tuning_hint(const ConsoleState& s) {
  if (s.run.mode != RunProgress::Mode::kIdle || s.engine_state == EngineState::kRunning) {
    return "Up/Down choose   changes wait: trials are running (x stops them)";
  }
  if (s.engine_state == EngineState::kFault) return "Up/Down choose   changes wait: a fault is latched (R resets)";
  if (s.tuning.selected == TuningForm::kLawRow)
    return "Up/Down choose   Enter or Right: next law   Left: the one before";
  return "Up/Down choose   Enter edit: type the value, Enter applies, Esc cancels";
}

}  // namespace

void render_tuning(const ConsoleState& s, Canvas& c, const Rect& body) {
  const Glyphs g = Glyphs::for_unicode(s.unicode);
  const int form_height = std::min(body.height, 15);
  const Rect form{body.x, body.y, body.width, form_height};
  c.frame(form, g, "Gains, learning law and weights (changed between trials)");
  const Rect in = inner(form);
  const auto& fields = tuning_fields();
  int y = in.y;
  c.put(in.x + 1, y++, "PID gains, normalized units: sent to the engine", Role::kTitle, true);
  for (int row = 0; row < TuningForm::kRows && y < in.bottom(); ++row) {
    const bool selected = row == s.tuning.selected;
    const int field = TuningForm::field_of(row);
    if (field < 0) {
      c.put(in.x + 1, y++,
            "Learning law: Enter or Right the next of " + std::to_string(learning_law_names().size()) +
                ", Left the one before",
            Role::kTitle, true);
      if (y >= in.bottom()) break;
      const std::string line = format("%s %-5s %12s %-4s  %-24s %s", selected ? ">" : " ", "law",
                                      s.config.ilc.law.c_str(), "", "[ilc] law", law_summary(s.config.ilc.law).c_str());
      c.put(in.x + 1, y++, fit(line, in.width - 1), selected ? Role::kSelected : Role::kNormal, selected);
      continue;
    }
    if (field == TuningForm::kLawRow) {  // M, the first weight
      const bool norm_optimal = s.law_name.rfind("noilc", 0) == 0;
      c.put(in.x + 1, y++,
            norm_optimal ? "Learning weights M, S, W (times I): the law " + s.law_name + " is rebuilt"
                         : "Learning weights M, S, W: not used by the law " + s.law_name,
            norm_optimal ? Role::kTitle : Role::kDim, true);
      if (y >= in.bottom()) break;
    }
    const TuningField& f = fields[static_cast<std::size_t>(field)];
    const std::string line = format("%s %-5s %12.6g %-4s  %-24s %s", selected ? ">" : " ", f.label,
                                    tuning_value(s.config, field), f.unit, f.config_key, f.description);
    c.put(in.x + 1, y++, fit(line, in.width - 1), selected ? Role::kSelected : Role::kNormal, selected);
  }
  for (const std::string& line : wrap(s.convergence, in.width - 2)) {  // two lines at most fit
    if (y >= in.bottom()) break;
    c.put(in.x + 1, y++, line, s.convergence_warning ? Role::kWarning : Role::kDim, s.convergence_warning, in.right());
  }
  if (form_height < body.height) {  // how to edit, under the form
    c.put(body.x + 2, form.bottom(), tuning_hint(s), Role::kKey, false, body.right() - 1);
  }
  const Rect changes{body.x, form.bottom() + 1, body.width, body.height - form_height - 1};
  if (changes.height < 3) return;
  c.frame(changes, g, "Changes recorded in the log");
  const Rect cin = inner(changes);
  std::vector<const LogEntry*> recorded;
  for (const LogEntry& e : s.log.entries()) {
    if (e.source == LogSource::kOperator && e.text.find(" changed ") != std::string::npos) recorded.push_back(&e);
  }
  const int count = static_cast<int>(recorded.size());
  for (int i = std::max(0, count - cin.height), row = 0; i < count; ++i, ++row) {
    const LogEntry& e = *recorded[static_cast<std::size_t>(i)];
    c.put(cin.x + 1, cin.y + row, e.clock + "  " + e.text, Role::kNormal, false, cin.right());
  }
  if (count == 0) c.put(cin.x + 1, cin.y, "none yet", Role::kDim);
}

namespace {

// The log screen's columns: clock, engine time, source, then the text, which wraps under itself.
constexpr int kLogTextColumn = 1 + 8 + 1 + 11 + 1 + 9;

int log_text_cells(const Rect& in) { return std::max(10, in.right() - (in.x + kLogTextColumn)); }

Rect log_inner(const ConsoleState& s) { return inner({0, 2, s.width, s.height - 4}); }

std::vector<std::string> log_entry_lines(const LogEntry& e, int cells) {
  std::vector<std::string> lines = wrap(e.text, cells);
  if (lines.empty()) lines.emplace_back();
  return lines;
}

}  // namespace

int log_top_scroll(const ConsoleState& s) {
  const Rect in = log_inner(s);
  const auto& entries = s.log.entries();
  const int count = static_cast<int>(entries.size());
  int rows = 0, last = -1;  // the newest entry that still fits whole below the oldest
  for (int i = 0; i < count; ++i) {
    rows += static_cast<int>(log_entry_lines(entries[static_cast<std::size_t>(i)], log_text_cells(in)).size());
    if (rows > in.height) break;
    last = i;
  }
  return last < 0 ? 0 : count - 1 - last;
}

void render_log(const ConsoleState& s, Canvas& c, const Rect& body) {
  const Glyphs g = Glyphs::for_unicode(s.unicode);
  c.frame(body, g, format("Event log (%zu entries)", s.log.entries().size()));
  const Rect in = inner(body);
  const auto& entries = s.log.entries();
  const int count = static_cast<int>(entries.size());
  const int last = std::max(0, count - 1 - s.log_scroll);
  // Long entries wrap under their text: nothing the operator or the engine said is cut off.
  const int text_x = in.x + kLogTextColumn;
  const int cells = log_text_cells(in);
  struct Row {
    const LogEntry* entry;
    std::string text;
    bool first;
  };
  std::vector<Row> page;  // oldest first
  int i = last;
  for (; i >= 0 && static_cast<int>(page.size()) < in.height; --i) {
    const LogEntry& e = entries[static_cast<std::size_t>(i)];
    const std::vector<std::string> lines = log_entry_lines(e, cells);
    for (std::size_t j = lines.size(); j-- > 0;) page.insert(page.begin(), {&e, lines[j], j == 0});
  }
  if (static_cast<int>(page.size()) > in.height)
    page.erase(page.begin(), page.end() - in.height);  // the oldest cut at the top
  // At the top (the oldest entry shown) a page is still full: newer entries fill it below.
  for (int k = last + 1; i < 0 && k < count && static_cast<int>(page.size()) < in.height; ++k) {
    const LogEntry& e = entries[static_cast<std::size_t>(k)];
    const std::vector<std::string> lines = log_entry_lines(e, cells);
    for (std::size_t j = 0; j < lines.size() && static_cast<int>(page.size()) < in.height; ++j)
      page.push_back({&e, lines[j], j == 0});
  }
  for (int r = 0; r < static_cast<int>(page.size()); ++r) {
    const Row& row = page[static_cast<std::size_t>(r)];
    const int y = in.y + r;
    const LogEntry& e = *row.entry;
    if (row.first) {
      int x = c.put(in.x + 1, y, e.clock, Role::kDim);
      x = c.put(x + 1, y, e.engine_time_s >= 0.0 ? format("%9.2f s", e.engine_time_s) : std::string(11, ' '),
                Role::kDim);
      c.put(x + 1, y, fit(to_string(e.source), 9), Role::kTitle);
    }
    c.put(text_x, y, row.text, e.important ? Role::kWarning : Role::kNormal, e.important, in.right());
  }
}

void render_sessions(const ConsoleState& s, Canvas& c, const Rect& body) {
  const Glyphs g = Glyphs::for_unicode(s.unicode);
  c.frame(body, g, "Saved sessions");
  const Rect in = inner(body);
  const SessionBrowser& b = s.browser;
  if (!s.sessions_available) {
    c.put(in.x + 1, in.y, "Not available: " + s.sessions_unavailable_reason, Role::kWarning, true, in.right());
    return;
  }
  if (b.loading) {
    c.put(in.x + 1, in.y, "Reading the saved sessions...", Role::kDim);
    return;
  }
  if (!b.error.empty()) c.put(in.x + 1, in.bottom() - 1, b.error, Role::kWarning, true, in.right());
  if (b.sessions.empty()) {
    c.put(in.x + 1, in.y, "No saved session yet: s saves the current one.", Role::kDim);
    return;
  }
  c.put(in.x + 1, in.y, "  started           device trajectory  iterations   best RMS  name", Role::kDim);
  const int rows = in.height - 3;  // the last line tells why the chosen one cannot be opened
  const int count = static_cast<int>(b.sessions.size());
  const int first = std::clamp(b.selected - rows + 1, 0, std::max(0, count - rows));
  for (int i = first, y = in.y + 1; i < count && y < in.y + 1 + rows; ++i, ++y) {
    const SessionListing& l = b.sessions[static_cast<std::size_t>(i)];
    const bool selected = i == b.selected;
    std::string row;
    if (l.error.empty()) {
      row = format("%s %-17s %-6s %-12s %9s   %s  %s%s", selected ? ">" : " ", l.date.c_str(), l.device.c_str(),
                   l.trajectory.c_str(), iteration_range(l.iterations).c_str(),
                   l.best_rms_deg >= 0.0 ? format("%8.3f", l.best_rms_deg).c_str() : "       -", l.name.c_str(),
                   l.refusal.empty() ? "" : "  (other device)");
    } else {
      row = format("%s %s: cannot be read: %s", selected ? ">" : " ", l.name.c_str(), l.error.c_str());
    }
    const bool openable = l.error.empty() && l.refusal.empty();
    c.put(in.x + 1, y, fit(row, in.width - 1), selected ? Role::kSelected : (openable ? Role::kNormal : Role::kDim),
          selected);
  }
  if (b.selected >= 0 && b.selected < count) {
    const SessionListing& l = b.sessions[static_cast<std::size_t>(b.selected)];
    if (!l.refusal.empty() && b.error.empty()) {
      c.put(in.x + 1, in.bottom() - 1, "cannot open it here: " + l.refusal, Role::kWarning, true, in.right());
    }
  }
}

}  // namespace bellows::ui::detail
