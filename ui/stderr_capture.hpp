#pragma once
// What other threads write to stderr while the console owns the terminal (a rig link's "no answer
// within 2.7 ms" from its I/O thread) would be painted over the ncurses screen at the cursor and
// stay there until the next full repaint. While a StderrCapture lives, stderr is a pipe the UI
// thread drains into the console's log instead; it is restored (and anything still unread goes to
// the real stderr) when the capture ends.

#include <string>
#include <vector>

namespace bellows::ui {

class StderrCapture {
 public:
  /// Redirects stderr. If the pipe cannot be made, stderr stays as it was (active() false).
  StderrCapture();
  ~StderrCapture();
  StderrCapture(const StderrCapture&) = delete;
  StderrCapture& operator=(const StderrCapture&) = delete;

  bool active() const { return read_fd_ >= 0; }
  /// The complete lines written since the last call, without their newline; never blocks.
  std::vector<std::string> drain();
  /// Gives stderr back now (what is unread goes to it); drain() returns nothing afterwards.
  void restore();

 private:
  int read_fd_ = -1;
  int saved_fd_ = -1;  // the real stderr
  std::string partial_;
};

}  // namespace bellows::ui
