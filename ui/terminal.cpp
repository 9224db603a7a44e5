#include "ui/terminal.hpp"

#include <langinfo.h>
#include <termios.h>
#include <unistd.h>

#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>

#include <ncurses.h>

#include "engine/base/errors.hpp"
#include "ui/keys.hpp"

namespace bellows::ui {
namespace {

enum Pair : short {
  kPairTitle = 1,
  kPairKey,
  kPairSafe,
  kPairArmed,
  kPairRunning,
  kPairFault,
  kPairWarning,
  kPairGood,
  kPairSeries1,
  kPairSeries2,
  kPairSeries3,
  kPairCursor
};

attr_t colour_attributes(Role role, short& pair) {
  pair = 0;
  switch (role) {
    case Role::kNormal:
      return A_NORMAL;
    case Role::kDim:
      return A_DIM;
    case Role::kTitle:
      pair = kPairTitle;
      return A_NORMAL;
    case Role::kSelected:
      return A_REVERSE;
    case Role::kKey:
      pair = kPairKey;
      return A_NORMAL;
    case Role::kSafe:
      pair = kPairSafe;
      return A_BOLD;
    case Role::kArmed:
      pair = kPairArmed;
      return A_BOLD;
    case Role::kRunning:
      pair = kPairRunning;
      return A_BOLD;
    case Role::kFault:
      pair = kPairFault;
      return A_BOLD;
    case Role::kWarning:
      pair = kPairWarning;
      return A_BOLD;
    case Role::kGood:
      pair = kPairGood;
      return A_NORMAL;
    case Role::kSeries1:
      pair = kPairSeries1;
      return A_NORMAL;
    case Role::kSeries2:
      pair = kPairSeries2;
      return A_NORMAL;
    case Role::kSeries3:
      pair = kPairSeries3;
      return A_NORMAL;
    case Role::kCursor:
      pair = kPairCursor;
      return A_BOLD;
  }
  return A_NORMAL;
}

// Without colours every role that matters still differs: states in reverse video, keys too.
attr_t mono_attributes(Role role) {
  // NOLINTBEGIN(bugprone-branch-clone): a table, one role a line; equal attributes are the design
  switch (role) {
    case Role::kNormal:
      return A_NORMAL;
    case Role::kDim:
      return A_DIM;
    case Role::kTitle:
      return A_BOLD;
    case Role::kSelected:
      return A_REVERSE;
    case Role::kKey:
      return A_REVERSE;
    case Role::kSafe:
      return A_BOLD;
    case Role::kArmed:
      return A_REVERSE;
    case Role::kRunning:
      return A_REVERSE;
    case Role::kFault:
      return A_REVERSE | A_BOLD;
    case Role::kWarning:
      return A_BOLD;
    case Role::kGood:
      return A_NORMAL;
    case Role::kSeries1:
      return A_BOLD;
    case Role::kSeries2:
      return A_NORMAL;
    case Role::kSeries3:
      return A_UNDERLINE;
    case Role::kCursor:
      return A_REVERSE;
  }
  // NOLINTEND(bugprone-branch-clone)
  return A_NORMAL;
}

int translate(int status, wint_t ch) {
  if (status == ERR) return key::kNone;
  if (status == KEY_CODE_YES) {
    switch (ch) {
      case KEY_RESIZE:
        return key::kResize;
      case KEY_UP:
        return key::kUp;
      case KEY_DOWN:
        return key::kDown;
      case KEY_LEFT:
        return key::kLeft;
      case KEY_RIGHT:
        return key::kRight;
      case KEY_PPAGE:
        return key::kPageUp;
      case KEY_NPAGE:
        return key::kPageDown;
      case KEY_HOME:
        return key::kHome;
      case KEY_END:
        return key::kEnd;
      case KEY_BACKSPACE:
        return key::kBackspace;
      case KEY_ENTER:
        return key::kEnter;
      case KEY_F(1):
        return key::kF1;
      default:
        return key::kOther;  // said to do nothing, rather than ignored in silence
    }
  }
  switch (ch) {
    case '\n':
    case '\r':
      return key::kEnter;
    case 27:
      return key::kEscape;
    case 127:
    case 8:
      return key::kBackspace;
    case '\t':
      return key::kTab;
    default:
      return static_cast<int>(ch);
  }
}

}  // namespace

bool locale_is_utf8() {
  const char* codeset = nl_langinfo(CODESET);
  return codeset != nullptr && (std::strcmp(codeset, "UTF-8") == 0 || std::strcmp(codeset, "utf8") == 0);
}

Terminal::Terminal(bool allow_colors) {
  if (isatty(STDIN_FILENO) == 0 || isatty(STDOUT_FILENO) == 0) {
    throw InputError("the console needs a terminal on stdin and stdout (for headless runs: bellows run)");
  }
  // Suspending the console (Ctrl-Z) would stop the engine thread with it: ignored. Set before
  // newterm, which then leaves SIGTSTP alone.
  std::signal(SIGTSTP, SIG_IGN);
  const char* term = std::getenv("TERM");
  SCREEN* screen = newterm(term, stdout, stdin);
  if (screen == nullptr) {
    throw InputError(std::string("cannot open the terminal '") + (term != nullptr ? term : "") +
                     "': is TERM set to a known terminal?");
  }
  screen_ = screen;
  set_term(screen);
  cbreak();
  // No XON/XOFF flow control: Ctrl-S would stop the output, the UI thread would block writing the
  // screen, its heartbeats would stop and the engine would fault. Ctrl-S and Ctrl-Q become keys.
  termios modes{};
  if (tcgetattr(STDIN_FILENO, &modes) == 0) {
    modes.c_iflag &= ~static_cast<tcflag_t>(IXON | IXOFF);
    tcsetattr(STDIN_FILENO, TCSANOW, &modes);
    def_prog_mode();  // ncurses restores these modes, not its own copy, after a repaint
  }
  noecho();
  nonl();
  keypad(stdscr, TRUE);
  set_escdelay(25);
  curs_set(0);
  colors_ = allow_colors && has_colors() && std::getenv("NO_COLOR") == nullptr;
  if (colors_) {
    start_color();
    use_default_colors();
    init_pair(kPairTitle, COLOR_CYAN, -1);
    init_pair(kPairKey, COLOR_BLACK, COLOR_CYAN);
    init_pair(kPairSafe, COLOR_BLACK, COLOR_GREEN);
    init_pair(kPairArmed, COLOR_BLACK, COLOR_YELLOW);
    init_pair(kPairRunning, COLOR_WHITE, COLOR_BLUE);
    init_pair(kPairFault, COLOR_WHITE, COLOR_RED);
    init_pair(kPairWarning, COLOR_YELLOW, -1);
    init_pair(kPairGood, COLOR_GREEN, -1);
    init_pair(kPairSeries1, COLOR_YELLOW, -1);
    init_pair(kPairSeries2, COLOR_CYAN, -1);
    init_pair(kPairSeries3, COLOR_MAGENTA, -1);
    init_pair(kPairCursor, COLOR_RED, -1);
  }
}

Terminal::~Terminal() {
  endwin();
  delscreen(static_cast<SCREEN*>(screen_));
}

int Terminal::width() const { return getmaxx(stdscr); }
int Terminal::height() const { return getmaxy(stdscr); }

void Terminal::repaint() { clearok(curscr, TRUE); }

int Terminal::read_key(int timeout_ms) {
  wtimeout(stdscr, timeout_ms);
  wint_t ch = 0;
  const int status = wget_wch(stdscr, &ch);
  if (status == OK && ch == 27) {
    // Esc with more input already behind it is Alt+key or an escape sequence ncurses does not know
    // (a function key split on a slow link): all of it is one key the console has no use for. Read
    // as Esc and then letters, it would close a prompt and run the letters as commands.
    wtimeout(stdscr, 0);
    bool more = false;
    wint_t next = 0;
    while (wget_wch(stdscr, &next) != ERR) more = true;
    if (more) return key::kOther;
  }
  return translate(status, ch);
}

void Terminal::draw(const Canvas& canvas) {
  const int rows = std::min(canvas.height(), height());
  const int cols = std::min(canvas.width(), width());
  std::wstring run;
  for (int y = 0; y < rows; ++y) {
    int x = 0;
    while (x < cols) {
      const Cell& first = canvas.at(x, y);
      short pair = 0;
      attr_t attributes = colors_ ? colour_attributes(first.role, pair) : mono_attributes(first.role);
      if (first.bold) attributes |= A_BOLD;
      run.clear();
      const int start = x;
      while (x < cols && canvas.at(x, y).role == first.role && canvas.at(x, y).bold == first.bold) {
        // A wide glyph covers the cell after it: ncurses advances two columns for it.
        if (canvas.at(x, y).glyph != kWideContinuation) run.push_back(static_cast<wchar_t>(canvas.at(x, y).glyph));
        ++x;
      }
      attr_set(attributes, pair, nullptr);
      mvaddnwstr(y, start, run.c_str(), static_cast<int>(run.size()));  // the last cell may report ERR: harmless
    }
  }
  attr_set(A_NORMAL, 0, nullptr);
  wnoutrefresh(stdscr);
  doupdate();
}

}  // namespace bellows::ui
