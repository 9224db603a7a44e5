// The screens and the pieces they share (internal to ui/).
#pragma once

#include <string>

#include "ui/canvas.hpp"
#include "ui/console_state.hpp"

namespace bellows::ui::detail {

Role state_role(EngineState state);
const char* state_words(EngineState state);
double to_deg(double rad);
/// format(fmt, value) without the sign of a zero that rounding made negative ("-0.00").
std::string number(const char* fmt, double value);
/// Inside of a frame: the area minus its border.
Rect inner(const Rect& area);

void render_dashboard(const ConsoleState& s, Canvas& c, const Rect& body);
void render_inspector(const ConsoleState& s, Canvas& c, const Rect& body);
void render_fault(const ConsoleState& s, Canvas& c, const Rect& body);
void render_help(const ConsoleState& s, Canvas& c, const Rect& body);
/// How many lines the help has at the window width (the controller bounds its scrolling by it).
int help_line_count(const ConsoleState& s);
void render_trajectory(const ConsoleState& s, Canvas& c, const Rect& body);
void render_tuning(const ConsoleState& s, Canvas& c, const Rect& body);
void render_log(const ConsoleState& s, Canvas& c, const Rect& body);
/// The log screen's scroll (entries back from the newest) at which its oldest entry is on the
/// first row: PgUp and Home stop there (the controller bounds its scrolling by it).
int log_top_scroll(const ConsoleState& s);
void render_sessions(const ConsoleState& s, Canvas& c, const Rect& body);
void render_rig(const ConsoleState& s, Canvas& c, const Rect& body);
/// The newest log entries that fit in `area`, one a line, without the routine ones.
void render_log_lines(const ConsoleState& s, Canvas& c, const Rect& area);

}  // namespace bellows::ui::detail
