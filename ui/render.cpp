#include "ui/render.hpp"

#include <algorithm>
#include <numbers>

#include "ui/joint_view.hpp"
#include "ui/key_map.hpp"
#include "ui/render_parts.hpp"

namespace bellows::ui {
namespace detail {

Role state_role(EngineState state) {
  switch (state) {
    case EngineState::kSafe:
      return Role::kSafe;
    case EngineState::kArmed:
      return Role::kArmed;
    case EngineState::kRunning:
      return Role::kRunning;
    case EngineState::kFault:
      return Role::kFault;
  }
  return Role::kNormal;
}

const char* state_words(EngineState state) {
  switch (state) {
    case EngineState::kSafe:
      return "vented";
    case EngineState::kArmed:
      return "valves live";
    case EngineState::kRunning:
      return "trial running";
    case EngineState::kFault:
      return "vented, latched";
  }
  return "";
}

double to_deg(double rad) { return rad * 180.0 / std::numbers::pi; }

std::string number(const char* fmt, double value) {
  std::string text = format(fmt, value);
  const auto minus = text.find('-');
  if (minus != std::string::npos && text.find_first_of("123456789") == std::string::npos) {
    text[minus] = ' ';  // a fixed-width field keeps its width
    if (minus == 0) text.erase(0, 1);
  }
  return text;
}

Rect inner(const Rect& a) { return {a.x + 1, a.y + 1, a.width - 2, a.height - 2}; }

void render_log_lines(const ConsoleState& s, Canvas& c, const Rect& area) {
  std::vector<const LogEntry*> shown;
  const auto& entries = s.log.entries();
  for (auto it = entries.rbegin(); it != entries.rend() && static_cast<int>(shown.size()) < area.height; ++it) {
    if (!it->routine) shown.push_back(&*it);
  }
  int y = area.y;
  for (auto it = shown.rbegin(); it != shown.rend(); ++it, ++y) {
    const LogEntry& e = **it;
    int x = c.put(area.x, y, e.clock + " ", Role::kDim, false, area.right());
    const Role role = e.important ? Role::kWarning : (e.source == LogSource::kOperator ? Role::kNormal : Role::kTitle);
    c.put(x, y, e.text, role, e.important, area.right());
  }
}

}  // namespace detail

namespace {

using namespace detail;

struct Segment {
  int gap;  // blank columns before it
  std::string text;
  Role role;
  bool bold;
};

void put_segments(Canvas& c, int y, const std::vector<Segment>& segments) {
  int x = 0;
  for (const Segment& g : segments) x = c.put(x + g.gap, y, g.text, g.role, g.bold);
}

int segments_width(const std::vector<Segment>& segments) {
  int width = 0;
  for (const Segment& g : segments) width += g.gap + text_width(g.text);
  return width;
}

/// The first line: what must be seen at a glance. Narrow windows get a compact form (the best RMS
/// dropped, then the labels and the state's words, then both) so that the state, trajectory,
/// iteration and RMS stay on screen down to 80 columns whatever the state.
std::vector<Segment> header_segments(const ConsoleState& s, int level) {
  const bool labels = level < 2;
  const bool best = level % 2 == 0;
  std::vector<Segment> out;
  out.push_back({0, " Bellows ", Role::kTitle, true});
  std::string state = format(" %s ", to_string(s.engine_state));
  if (s.engine_state == EngineState::kFault) state = format(" FAULT: %s ", fault_name(s.fault));
  out.push_back({1, state, state_role(s.engine_state), true});
  if (labels) out.push_back({0, format(" %s ", state_words(s.engine_state)), Role::kDim, false});
  if (labels) out.push_back({1, "device ", Role::kDim, false});
  out.push_back(
      {labels ? 0 : 2, s.device.name + ": " + s.device.status, s.device.ok ? Role::kGood : Role::kWarning, false});
  const Experiment& e = s.experiment;
  if (e.trajectory) {
    if (labels) out.push_back({2, "trajectory ", Role::kDim, false});
    out.push_back({labels ? 0 : 2, format("%s (%.1f s)", e.trajectory->name.c_str(), e.trajectory->duration_s()),
                   Role::kNormal, true});
  }
  // The joint the screens show, on an arm with several (j selects it).
  if (e.joints() > 1) out.push_back({2, joint_label(e.joints(), selected_joint(s)), Role::kNormal, true});
  // The newest iteration run, whose RMS follows (docs/iterations.md); "-" before the first.
  out.push_back({2, labels ? "iteration " : "it ", Role::kDim, false});
  out.push_back(
      {0, e.trials.empty() ? std::string("-") : format("%d", e.trials.back().iteration), Role::kNormal, true});
  if (!e.trials.empty()) {
    out.push_back({2, "RMS ", Role::kDim, false});
    out.push_back({0, format("%.3f deg", e.trials.back().summary.rms_deg), Role::kNormal, true});
    if (best) out.push_back({0, format(" (best %.3f)", e.best_rms_deg()), Role::kDim, false});
  }
  return out;
}

/// The weights and gains the law `ilc.law` learns with, and only those.
std::string law_weights(const IlcParameters& ilc) {
  if (ilc.law == "pd") return format("k_p %g k_d %g s Q %g Hz", ilc.pd_kp, ilc.pd_kd_s, ilc.pd_q_cutoff_hz);
  if (ilc.law == "gradient") return format("step %g", ilc.gradient_step);
  if (ilc.law == "inverse") return format("gain %g Q %g Hz", ilc.inverse_gain, ilc.inverse_q_cutoff_hz);
  return format("M %g S %g W %g", ilc.m, ilc.s, ilc.w);  // the norm-optimal laws
}

/// The second line: loop health and the learning; compact forms drop the weights (the tuning
/// screen shows them), then shorten the latency, then drop its labels.
std::vector<Segment> loop_segments(const ConsoleState& s, int level) {
  const LoopHealth& l = s.loop;
  std::vector<Segment> out;
  out.push_back({1, level < 3 ? "loop " : "", Role::kDim, false});
  out.push_back({0, format("%.0f Hz x%s%s%s", l.tick_hz, l.speed.c_str(), l.rt.empty() ? "" : " ", l.rt.c_str()),
                 Role::kNormal, false});
  // Which clock runs: a simulated one repeats `bellows run`'s numbers; the wall clock does not.
  out.push_back({1, level < 2 ? l.clock + " clock" : l.clock, l.clock == "sim" ? Role::kGood : Role::kDim, false});
  out.push_back({2, "missed ", Role::kDim, false});
  out.push_back({0, format("%llu", static_cast<unsigned long long>(l.missed)),
                 l.missed > 0 ? Role::kWarning : Role::kGood, false});
  if (l.realtime && l.speed != "max") {
    out.push_back({2, level < 3 ? "latency " : "", Role::kDim, false});
    out.push_back({0,
                   level < 2 ? format("p50 %.0f p99 %.0f max %.0f us", l.p50_us, l.p99_us, l.max_us)
                             : format("p99 %.0f max %.0f us", l.p99_us, l.max_us),
                   Role::kNormal, false});
  } else if (l.realtime) {
    out.push_back({2, "unpaced", Role::kDim, false});
  }
  out.push_back({2, "law ", Role::kDim, false});
  out.push_back(
      {0, s.law_name + (s.law_ready ? "" : " (preparing)"), s.law_ready ? Role::kNormal : Role::kWarning, false});
  if (level == 0) out.push_back({2, law_weights(s.config.ilc), Role::kDim, false});
  if (l.dropped_events > 0) {  // a loss, said like every other
    out.push_back(
        {2, format("%llu events dropped", static_cast<unsigned long long>(l.dropped_events)), Role::kWarning, false});
  }
  if (s.experiment.unsaved() && !s.experiment.trials.empty()) out.push_back({2, "unsaved", Role::kWarning, false});
  return out;
}

void render_header(const ConsoleState& s, Canvas& c) {
  std::vector<Segment> line;
  for (int level = 0; level < 4; ++level) {
    line = header_segments(s, level);
    if (segments_width(line) <= c.width()) break;
  }
  put_segments(c, 0, line);
  for (int level = 0; level < 4; ++level) {
    line = loop_segments(s, level);
    if (segments_width(line) <= c.width()) break;
  }
  put_segments(c, 1, line);
}

/// The status line, never cut mid-word: a message longer than the window wraps onto the line above
/// (the body's bottom border), and one longer than two lines ends at a word with an ellipsis.
void render_status(const ConsoleState& s, Canvas& c) {
  const int y = c.height() - 2;
  std::string text = s.status_screen == s.screen ? s.status : std::string();  // said on another screen: not here
  if (s.learner_busy && !s.learner_task.empty()) text = s.learner_task + "...  " + text;
  if (s.heartbeat_drill) text = "HEARTBEAT DRILL: heartbeats withheld, the engine must vent  " + text;
  const int columns = c.width() - 2;
  std::vector<std::string> lines = wrap(text, columns);
  const std::string ellipsis = s.unicode ? "\u2026" : "...";
  if (lines.size() > 2) {
    lines.resize(2);
    std::vector<std::string> last = wrap(lines[1], columns - text_width(ellipsis) - 1);
    lines[1] = (last.empty() ? std::string() : last.front()) + " " + ellipsis;
  }
  const Role role = s.status_important || s.heartbeat_drill ? Role::kWarning : Role::kNormal;
  const int top = y - static_cast<int>(lines.size()) + 1;
  for (std::size_t i = 0; i < lines.size(); ++i) {
    const int row = top + static_cast<int>(i);
    c.fill({0, row, c.width(), 1}, U' ');
    c.put(1, row, lines[i], role, s.status_important);
  }
}

/// The htop-style bar: the keys that matter now. When they do not all fit, the stop, the way back,
/// help and quit stay, and the others are dropped from the end.
void render_function_bar(const ConsoleState& s, Canvas& c) {
  const int y = c.height() - 1;
  const std::vector<Action> candidates = function_bar_actions(s);
  const auto width_of = [](Action a) {
    const KeyBinding& b = binding(a);
    return text_width(a == Action::kEmergencyStop ? "Space" : b.key_label) + text_width(b.bar_label) + 3;
  };
  const auto essential = [](Action a) {
    return a == Action::kEmergencyStop || a == Action::kMain || a == Action::kHelp || a == Action::kQuit;
  };
  int room = c.width();
  for (Action a : candidates) {
    if (essential(a)) room -= width_of(a);
  }
  std::vector<Action> shown;
  for (Action a : candidates) {
    if (essential(a)) {
      shown.push_back(a);
    } else if (width_of(a) <= room) {
      shown.push_back(a);
      room -= width_of(a);
    } else {
      room = 0;  // keep the order: nothing after a dropped key jumps ahead of it
    }
  }
  int x = 0;
  for (Action a : shown) {
    const KeyBinding& b = binding(a);
    const std::string key = a == Action::kEmergencyStop ? "Space" : b.key_label;
    if (x + width_of(a) - 2 > c.width()) break;
    x = c.put(x, y, key, Role::kKey, true);
    x = c.put(x, y, " ");
    x = c.put(x, y, b.bar_label, a == Action::kEmergencyStop ? Role::kFault : Role::kTitle, true);
    x = c.put(x, y, "  ");
  }
}

void render_dialog(const ConsoleState& s, Canvas& c) {
  const Dialog& d = s.dialog;
  const Glyphs g = Glyphs::for_unicode(s.unicode);
  int content_width = text_width(d.title) + 4;
  for (const std::string& line : d.text) content_width = std::max(content_width, text_width(line));
  content_width = std::max({content_width, text_width(d.hint), text_width(d.error), 40});
  const int width = std::min(content_width + 4, c.width() - 4);
  const bool has_input = d.kind == DialogKind::kAskIterations || d.kind == DialogKind::kTrajectoryPath ||
                         d.kind == DialogKind::kEditValue || d.kind == DialogKind::kSessionName;
  const std::vector<std::string> error = d.error.empty() ? std::vector<std::string>{} : wrap(d.error, width - 4);
  std::vector<std::string> text;  // wrapped at words, never cut, when the window is narrower than a line
  for (const std::string& line : d.text) {
    if (line.empty()) text.emplace_back();
    for (std::string& part : wrap(line, width - 4)) text.push_back(std::move(part));
  }
  const int height = static_cast<int>(text.size() + error.size()) + (has_input ? 2 : 0) + 4;
  const Rect box{(c.width() - width) / 2, std::max(2, (c.height() - height) / 2), width, height};
  c.fill(box, U' ');
  c.frame(box, g, d.title, Role::kWarning);
  int y = box.y + 1;
  for (const std::string& line : text) c.put(box.x + 2, y++, line, Role::kNormal, false, box.right() - 2);
  if (has_input) {
    ++y;
    const int field = box.width - 6;
    const std::string visible = tail_fit(d.input, field - 1);  // the end of a long input, by display width
    c.put(box.x + 2, y, "> ", Role::kKey, true);
    c.put(box.x + 4, y, fit(visible + "_", field), Role::kSelected);
    ++y;
  }
  for (const std::string& line : error) c.put(box.x + 2, y++, line, Role::kWarning, true, box.right() - 2);
  c.put(box.x + 2, box.bottom() - 2, d.hint, Role::kDim, false, box.right() - 2);
}

void render_too_small(const ConsoleState& s, Canvas& c) {
  std::vector<std::string> lines = {
      "Terminal too small",
      format("%dx%d: Bellows needs at least %dx%d.", s.width, s.height, kMinWidth, kMinHeight),
      "Enlarge the window to see the console.",
      format("Engine: %s", to_string(s.engine_state)),
      "Space: emergency stop    q: quit",
  };
  if (s.dialog.kind != DialogKind::kNone) {  // a question waits for an answer: say which
    lines.push_back(s.dialog.title);
    lines.push_back(s.dialog.hint);
  }
  const int top = std::max(0, (c.height() - static_cast<int>(lines.size())) / 2);
  for (std::size_t i = 0; i < lines.size(); ++i) {
    const int y = top + static_cast<int>(i);
    const int x = std::max(0, (c.width() - text_width(lines[i])) / 2);
    const Role role = i == 0 ? Role::kWarning : (i == 3 ? state_role(s.engine_state) : Role::kNormal);
    c.put(x, y, lines[i], role, i == 0);
  }
}

}  // namespace

void render(const ConsoleState& s, Canvas& c) {
  c.clear();
  if (c.width() < kMinWidth || c.height() < kMinHeight) {
    render_too_small(s, c);
    return;
  }
  render_header(s, c);
  const Rect body{0, 2, c.width(), c.height() - 4};
  switch (s.screen) {
    case Screen::kMain:
      render_dashboard(s, c, body);
      break;
    case Screen::kInspector:
      render_inspector(s, c, body);
      break;
    case Screen::kFault:
      render_fault(s, c, body);
      break;
    case Screen::kHelp:
      render_help(s, c, body);
      break;
    case Screen::kTrajectory:
      render_trajectory(s, c, body);
      break;
    case Screen::kTuning:
      render_tuning(s, c, body);
      break;
    case Screen::kLog:
      render_log(s, c, body);
      break;
    case Screen::kSessions:
      render_sessions(s, c, body);
      break;
    case Screen::kRig:
      render_rig(s, c, body);
      break;
  }
  render_status(s, c);
  render_function_bar(s, c);
  if (s.dialog.kind != DialogKind::kNone) render_dialog(s, c);
}

std::vector<std::string> render_lines(const ConsoleState& state) {
  Canvas canvas(state.width, state.height);
  render(state, canvas);
  return canvas.lines();
}

}  // namespace bellows::ui
