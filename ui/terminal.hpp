// The only code that touches ncurses, and only from the UI thread: opens the terminal, reads keys
// with a timeout (translated to ui/keys.hpp codes), copies a Canvas to the screen with colours,
// or with attributes alone when the terminal has none (or NO_COLOR is set).
#pragma once

#include "ui/canvas.hpp"

namespace bellows::ui {

/// Whether the current locale is UTF-8 (call setlocale(LC_ALL, "") first).
bool locale_is_utf8();

class Terminal {
 public:
  /// Opens the terminal on stdin/stdout. Throws InputError when they are not a usable terminal.
  explicit Terminal(bool allow_colors);
  ~Terminal();
  Terminal(const Terminal&) = delete;
  Terminal& operator=(const Terminal&) = delete;

  int width() const;
  int height() const;
  bool colors() const { return colors_; }
  /// A key, or key::kNone when none came within `timeout_ms`. KEY_RESIZE comes back as key::kResize.
  int read_key(int timeout_ms);
  void draw(const Canvas& canvas);
  /// The next draw repaints every cell of the terminal, not only what changed (Ctrl-L).
  void repaint();

 private:
  void* screen_ = nullptr;  // SCREEN*
  bool colors_ = false;
};

}  // namespace bellows::ui
