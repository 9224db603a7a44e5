// Rendering, separated from ncurses: the whole screen for a ConsoleState, as styled cells. The
// terminal copies the canvas to the screen; tests and the docs read it as text.
#pragma once

#include <string>
#include <vector>

#include "ui/canvas.hpp"
#include "ui/console_state.hpp"

namespace bellows::ui {

inline constexpr int kMinWidth = 80;
inline constexpr int kMinHeight = 24;

/// Draws the screen for `state` into `canvas` (whose size is the terminal's).
void render(const ConsoleState& state, Canvas& canvas);
/// The screen as text lines, at the state's size.
std::vector<std::string> render_lines(const ConsoleState& state);

}  // namespace bellows::ui
